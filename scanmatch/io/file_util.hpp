#pragma once
// Whole-file reading (gzip/zlib decompressed transparently) and atomic whole-file writing.

#include <cstddef>
#include <string>

namespace scanmatch {

/// Maximum size a decompressed input may reach before it is refused (guards against zip bombs).
inline constexpr std::size_t kMaxInputBytes = std::size_t{4} << 30;

/// The file's bytes; if they start with the gzip magic (or the name ends in ".gz") they are
/// inflated. Throws Error naming the file when it is missing, unreadable or corrupt.
std::string read_file_bytes(const std::string& path);

/// Writes `bytes` to `path` through a temporary file in the same folder and a rename, so readers
/// never see a half-written file. Throws Error naming the file on failure.
void write_file_atomic(const std::string& path, const std::string& bytes);

/// Lower-case extension without the dot, ignoring a trailing ".gz" ("a/b.PCD.gz" -> "pcd").
std::string extension_without_gz(const std::string& path);

}  // namespace scanmatch
