#pragma once
// PCD (Point Cloud Library format): DATA ascii, binary and binary_compressed (LZF).

#include <string>
#include <string_view>

#include "scanmatch/io/cloud_io.hpp"

namespace scanmatch {

PointCloud parse_pcd(std::string_view bytes, const std::string& source,
                     const CloudReadOptions& options, CloudFileInfo* info);
std::string format_pcd(const PointCloud& cloud, CloudWriteOptions::Encoding encoding);

}  // namespace scanmatch
