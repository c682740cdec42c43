#pragma once
// Per-frame outputs (poses, timing.csv): a text file created at once and appended a line at a
// time, each line flushed, so an interrupted or failed run keeps every line it wrote.

#include <cstdio>
#include <string>
#include <string_view>

namespace scanmatch {

class LineWriter {
 public:
  /// Creates (truncates) `path`; throws Error naming it when it cannot.
  explicit LineWriter(const std::string& path);
  ~LineWriter();
  LineWriter(const LineWriter&) = delete;
  LineWriter& operator=(const LineWriter&) = delete;
  /// Appends `text` and a newline and flushes; throws Error naming the file on failure.
  void line(std::string_view text);
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::FILE* file_ = nullptr;
};

}  // namespace scanmatch
