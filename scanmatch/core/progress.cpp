#include "scanmatch/core/progress.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdio>

namespace scanmatch {

bool ProgressReporter::stderr_is_terminal() {
  return isatty(STDERR_FILENO) == 1;
}

ProgressReporter::ProgressReporter(std::string label, std::size_t total, std::string unit,
                                   bool quiet)
    : label_(std::move(label)),
      unit_(std::move(unit)),
      total_(total),
      enabled_(!quiet && stderr_is_terminal()),
      start_(Clock::now()),
      last_draw_(start_) {}

ProgressReporter::~ProgressReporter() {
  finish();
}

void ProgressReporter::update(std::size_t done) {
  if (!enabled_) return;
  const auto now = Clock::now();
  if (drawn_ && now - last_draw_ < std::chrono::milliseconds(200) && done != total_) return;
  last_draw_ = now;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const double rate = elapsed > 0.0 ? static_cast<double>(done) / elapsed : 0.0;
  char line[256];
  if (total_ > 0 && rate > 0.0) {
    const double left = static_cast<double>(total_ - std::min(done, total_)) / rate;
    std::snprintf(line, sizeof line, "%s: %zu/%zu %s, %.1f %s/s, %s left", label_.c_str(), done,
                  total_, unit_.c_str(), rate, unit_.c_str(), format_duration(left).c_str());
  } else {
    std::snprintf(line, sizeof line, "%s: %zu %s, %.1f %s/s", label_.c_str(), done, unit_.c_str(),
                  rate, unit_.c_str());
  }
  std::fprintf(stderr, "\r\033[K%s", line);
  std::fflush(stderr);
  drawn_ = true;
}

void ProgressReporter::finish() {
  if (!enabled_ || !drawn_) return;
  std::fprintf(stderr, "\r\033[K");
  std::fflush(stderr);
  drawn_ = false;
}

std::string format_duration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0.0) seconds = 0.0;
  const long total = std::lround(seconds);
  char buffer[32];
  if (total >= 3600)
    std::snprintf(buffer, sizeof buffer, "%ld:%02ld:%02ld", total / 3600, (total / 60) % 60,
                  total % 60);
  else
    std::snprintf(buffer, sizeof buffer, "%ld:%02ld", total / 60, total % 60);
  return buffer;
}

}  // namespace scanmatch
