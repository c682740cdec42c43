#include "scanmatch/odometry/frame_stats.hpp"

#include <algorithm>

#include "scanmatch/io/record_csv.hpp"

namespace scanmatch {
namespace {

// Adds a frame's stage times to the stages, in the order of describe().
struct StageSums {
  std::vector<StageStatistics> stages;
  std::size_t next = 0;
  template <typename T>
  void operator()(const char*, const T&, const char*) {}
  void stage(const char*, double ms, const char* name, const char*) {
    if (next == stages.size()) stages.push_back({name});
    StageStatistics& s = stages[next++];
    s.mean_ms += ms;
    s.max_ms = std::max(s.max_ms, ms);
  }
};

}  // namespace

std::string timing_csv_header() {
  return record_csv_header<FrameStats>();
}

std::string timing_csv_row(std::size_t index, double timestamp, const FrameStats& stats) {
  return record_csv_row(index, timestamp, stats);
}

std::vector<FrameRecord> read_timing_csv(const std::string& path) {
  return read_record_csv<FrameStats>(path, "total_ms");
}

std::vector<StageStatistics> stage_statistics(const std::vector<FrameStats>& frames) {
  StageSums sum;
  const FrameStats defaults;
  describe(defaults, sum);  // the names, also without frames
  for (const FrameStats& frame : frames) {
    sum.next = 0;
    describe(frame, sum);
  }
  if (!frames.empty())
    for (StageStatistics& s : sum.stages) s.mean_ms /= static_cast<double>(frames.size());
  return sum.stages;
}

}  // namespace scanmatch
