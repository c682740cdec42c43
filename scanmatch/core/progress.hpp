#pragma once
// A one-line progress display for long work (frames done, rate, time left) on stderr. Silent when
// stderr is not a terminal or when disabled (--quiet), so logs and pipes stay clean.

#include <chrono>
#include <cstddef>
#include <string>

namespace scanmatch {

class ProgressReporter {
 public:
  /// `total` may be 0 when unknown (then no time left is shown). `unit` names the items ("frames").
  ProgressReporter(std::string label, std::size_t total, std::string unit = "frames",
                   bool quiet = false);
  ~ProgressReporter();
  ProgressReporter(const ProgressReporter&) = delete;
  ProgressReporter& operator=(const ProgressReporter&) = delete;

  /// Reports `done` items finished; redraws at most a few times per second.
  void update(std::size_t done);
  /// Clears the line (the caller prints its own summary).
  void finish();
  bool enabled() const { return enabled_; }

  /// True when stderr is an interactive terminal.
  static bool stderr_is_terminal();

 private:
  using Clock = std::chrono::steady_clock;
  std::string label_, unit_;
  std::size_t total_;
  bool enabled_;
  bool drawn_ = false;
  Clock::time_point start_, last_draw_;
};

/// "1:02:03" or "2:03" for a duration in seconds.
std::string format_duration(double seconds);

}  // namespace scanmatch
