#pragma once
// PLY: ascii, binary_little_endian and binary_big_endian; the vertex element's x y z and optional
// intensity, ring and time properties. Other elements (faces, ...) are skipped.

#include <string>
#include <string_view>

#include "scanmatch/io/cloud_io.hpp"

namespace scanmatch {

PointCloud parse_ply(std::string_view bytes, const std::string& source,
                     const CloudReadOptions& options, CloudFileInfo* info);
std::string format_ply(const PointCloud& cloud, CloudWriteOptions::Encoding encoding);

}  // namespace scanmatch
