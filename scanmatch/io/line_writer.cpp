#include "scanmatch/io/line_writer.hpp"

#include <cerrno>
#include <cstring>

#include "scanmatch/core/error.hpp"

namespace scanmatch {

LineWriter::LineWriter(const std::string& path)
    : path_(path), file_(std::fopen(path.c_str(), "w")) {
  if (!file_) fail(path, std::string("cannot create: ") + std::strerror(errno));
}

LineWriter::~LineWriter() {
  std::fclose(file_);
}

void LineWriter::line(std::string_view text) {
  if (std::fwrite(text.data(), 1, text.size(), file_) != text.size() ||
      std::fputc('\n', file_) == EOF || std::fflush(file_) != 0)
    fail(path_, std::string("write failed: ") + std::strerror(errno));
}

}  // namespace scanmatch
