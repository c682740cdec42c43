#pragma once
// Reading and writing point clouds: PCD (ascii, binary, binary_compressed), PLY (ascii, binary
// little/big endian), KITTI .bin (float32 x y z intensity) and plain text (.xyz, .txt, .csv).
// The format follows the file name's extension; a trailing ".gz" is decompressed transparently
// on reading. Every failure throws scanmatch::Error naming the file, the place and the problem.

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "scanmatch/core/point_cloud.hpp"

namespace scanmatch {

enum class CloudFormat { kPcd, kPly, kKittiBin, kText };

/// Format from the extension (".pcd", ".ply", ".bin", ".xyz"/".txt"/".csv", each optionally
/// followed by ".gz"); throws Error for anything else.
CloudFormat cloud_format_from_path(const std::string& path);
const char* to_string(CloudFormat format);

struct CloudReadOptions {
  /// Keep points with NaN or infinite coordinates (organised clouds need them); dropped by default.
  bool keep_non_finite = false;
};

/// What a reader learned about the file beyond the points themselves.
struct CloudFileInfo {
  CloudFormat format = CloudFormat::kPcd;
  std::string encoding;  ///< e.g. "ascii", "binary", "binary_compressed", "binary_big_endian"
  std::vector<std::string> fields;    ///< every field/property name in the file, in file order
  std::size_t width = 0, height = 0;  ///< organised layout (height 1 when unorganised)
  std::size_t points_in_file = 0;     ///< before non-finite removal
  std::size_t non_finite = 0;         ///< points with a NaN or infinite coordinate
  bool compressed_gzip = false;
};

/// Parses a cloud already in memory (used by read_cloud and the fuzzers); `source` names it in
/// errors.
PointCloud parse_cloud(std::string_view bytes, CloudFormat format, const std::string& source,
                       const CloudReadOptions& options = {}, CloudFileInfo* info = nullptr);

PointCloud read_cloud(const std::string& path, const CloudReadOptions& options = {},
                      CloudFileInfo* info = nullptr);

struct CloudWriteOptions {
  enum class Encoding { kBinary, kAscii, kBinaryCompressed };
  /// PCD: binary, ascii or binary_compressed. PLY: binary (little endian) or ascii.
  /// Text and KITTI .bin ignore it.
  Encoding encoding = Encoding::kBinary;
};

/// Writes atomically (temporary file in the same folder, then rename). Fields the cloud lacks are
/// not written (KITTI .bin always has intensity: 0 when absent).
void write_cloud(const std::string& path, const PointCloud& cloud,
                 const CloudWriteOptions& options = {});

}  // namespace scanmatch
