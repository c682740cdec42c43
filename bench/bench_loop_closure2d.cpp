// 2D loop closure's cost per keyframe (keyframes, odometry edges, candidates, verification,
// optimization) on sim:room-2d (no shared data needed): its 500 scans fed with their true poses
// as the odometry, so that every revisit is a candidate; with the defaults (no pause after a loop)
// and with a pause of one keyframe after each (keyframes_between_loops).
//   build/bench/scanmatch_bench --benchmark_filter=LoopClosure2D

#include <benchmark/benchmark.h>

#include "scanmatch/mapping/loop_closure2d.hpp"
#include "scanmatch/run/map2d_run.hpp"

namespace {
using namespace scanmatch;

struct PosedScans {
  std::vector<Scan2D> scans;
  std::vector<Pose2> poses;
};

const PosedScans& room() {
  static const PosedScans out = [] {
    const Scans2D input = load_scans_2d("sim:room-2d", {}, 500);
    PosedScans s;
    for (const LaserScan2D& scan : input.scans) {
      s.scans.push_back(scan_from_laser(scan, 0.05));
      s.poses.push_back(pose2(scan.pose));
    }
    return s;
  }();
  return out;
}

void BM_LoopClosure2D(benchmark::State& state, std::size_t keyframes_between_loops) {
  const PosedScans& s = room();
  LoopClosure2DOptions options;
  options.keyframes_between_loops = keyframes_between_loops;
  std::size_t keyframes = 0, candidates = 0;
  for (auto _ : state) {
    LoopClosure2D loops(options);
    for (std::size_t i = 0; i < s.scans.size(); ++i) loops.add_scan(s.scans[i], s.poses[i]);
    loops.finish();
    keyframes += loops.counts().keyframes;
    candidates += loops.counts().candidates;
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(keyframes));
  state.counters["candidates_per_keyframe"] =
      static_cast<double>(candidates) / static_cast<double>(std::max<std::size_t>(keyframes, 1));
}
BENCHMARK_CAPTURE(BM_LoopClosure2D, defaults, LoopClosure2DOptions{}.keyframes_between_loops)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_LoopClosure2D, pause_1, 1)->Unit(benchmark::kMillisecond);

}  // namespace
