#pragma once
// Small shared helpers for tests: temporary folders, writing literal files, the shared data path.

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

#include "scanmatch/core/error.hpp"
#include "scanmatch/core/point_cloud.hpp"

#include <cstdio>

namespace scanmatch::testing {

/// Under the sanitizers (scripts/test --sanitize) tests run on fewer frames.
inline bool sanitized() {
  return std::getenv("SCANMATCH_SANITIZED") != nullptr;
}

/// Clouds and their times (s), as a simulated sequence gives them.
struct TimedClouds {
  std::vector<PointCloud> clouds;
  std::vector<double> times;
};

/// Expects the same points and per-point fields, naming the first differing point.
inline void expect_same_cloud(const PointCloud& actual, const PointCloud& expected) {
  ASSERT_EQ(actual.size(), expected.size());
  for (std::size_t i = 0; i < actual.size(); ++i)
    EXPECT_EQ(actual.points[i], expected.points[i]) << "point " << i;
  EXPECT_EQ(actual.intensity, expected.intensity);
  EXPECT_EQ(actual.ring, expected.ring);
  EXPECT_EQ(actual.time, expected.time);
}

/// How often `what` occurs in `text` (overlapping occurrences count).
inline std::size_t count_occurrences(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

inline double degrees(double rad) {
  return rad * 180.0 / M_PI;
}

/// The upper median (the middle element, or the upper of the two middle ones); NaN when empty.
inline double median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

/// A fresh folder under the system temp dir, removed when the object goes away.
class TempDir {
 public:
  TempDir() {
    static std::atomic<int> counter{0};
    path_ = std::filesystem::temp_directory_path() /
            ("scanmatch_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

inline void write_text(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

/// The file's bytes (empty when it cannot be read).
inline std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// ../shared relative to the repository, or empty when absent.
inline std::string shared_data(const std::string& relative) {
  const std::filesystem::path p =
      std::filesystem::path(SCANMATCH_SOURCE_DIR) / ".." / "shared" / relative;
  return std::filesystem::exists(p) ? p.string() : std::string();
}

/// The message of the scanmatch::Error that `f` throws; empty when it throws none.
inline std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

struct CliRun {
  int status;
  std::string output;  ///< stdout and stderr together
};

/// Runs the built `scanmatch` CLI with `args` (shell syntax) and collects its output.
inline CliRun run_cli(const std::string& args) {
  const std::string command = std::string(SCANMATCH_CLI_PATH) + " " + args + " 2>&1";
  CliRun run{-1, ""};
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return run;
  char buffer[4096];
  std::size_t n;
  while ((n = fread(buffer, 1, sizeof buffer, pipe)) > 0) run.output.append(buffer, n);
  const int status = pclose(pipe);
  run.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

}  // namespace scanmatch::testing
