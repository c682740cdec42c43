#include "apps/file_kind.hpp"

#include <filesystem>

#include "scanmatch/core/error.hpp"
#include "scanmatch/io/file_util.hpp"

namespace scanmatch::cli {

FileKind detect_file_kind(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return FileKind::kSequence;
  const std::string ext = extension_without_gz(path);
  if (ext == "log" || ext == "clf") return FileKind::kCarmen;
  if (ext == "tum") return FileKind::kTrajectory;
  if (ext != "txt") return FileKind::kCloud;
  if (!std::filesystem::exists(path, ec)) return FileKind::kCloud;
  const std::string text = read_file_bytes(path);
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    const std::string line = text.substr(start, end - start);
    start = end + 1;
    const std::size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::size_t columns = 0;
    bool in_token = false;
    for (char c : line) {
      const bool sep = c == ' ' || c == '\t' || c == ',' || c == '\r';
      if (!sep && !in_token) ++columns;
      in_token = !sep;
    }
    return columns == 12 || columns == 8 ? FileKind::kTrajectory : FileKind::kCloud;
  }
  fail(path, "file is empty");
}

}  // namespace scanmatch::cli
