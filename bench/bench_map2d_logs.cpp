// The 2D odometry and its loop closure on the six shared Radish logs, on one thread, defaults: the
// odometry's registration time per scan (the bound: 10 ms), the loop closure's own time
// per scan fed inline with the odometry's poses, and its share of the two together, all measured
// in one run. Skipped where ../shared is absent.
//   build/bench/scanmatch_bench --benchmark_filter=Map2DLog

#include <benchmark/benchmark.h>

#include <tbb/global_control.h>

#include <filesystem>
#include <string>

#include "scanmatch/mapping/loop_closure2d.hpp"
#include "scanmatch/mapping2d/mapper2d.hpp"
#include "scanmatch/run/map2d_run.hpp"

namespace {
using namespace scanmatch;

void BM_Map2DLog(benchmark::State& state, const std::string& log) {
  const auto path = std::filesystem::path(SCANMATCH_SOURCE_DIR) / ".." / "shared" / "data" / "2d" /
                    "carmen" / (log + "-corrected.log.gz");
  if (!std::filesystem::exists(path)) {
    state.SkipWithError((path.string() + " is absent").c_str());
    return;
  }
  const Scans2D input = load_scans_2d(path.string());
  const Mapper2DConfig config;
  // One thread for both: the loop closure's candidates are otherwise verified side by side.
  const tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
  double odometry_ms = 0.0, loop_ms = 0.0;
  for (auto _ : state) {
    Mapper2D mapper(config);
    LoopClosure2D loops;
    odometry_ms = 0.0;
    for (const LaserScan2D& laser : input.scans) {
      const Scan2D scan = scan_from_laser(laser, config.min_range);
      const Pose2 pose = mapper.add_scan(scan, laser.timestamp);
      odometry_ms += mapper.last_stats().ms;
      const Scan2DStats& stats = mapper.last_stats();
      loops.add_scan(mapper.last_scan(), pose, stats.weak_fit, stats.unregistered());
    }
    loops.finish();
    loop_ms = loops.counts().total_ms;
    benchmark::DoNotOptimize(loops.poses());
  }
  const double scans = static_cast<double>(input.scans.size());
  state.counters["odometry_ms_per_scan"] = odometry_ms / scans;
  state.counters["loop_closure_ms_per_scan"] = loop_ms / scans;
  state.counters["loop_closure_share"] = loop_ms / (odometry_ms + loop_ms);
  state.SetItemsProcessed(static_cast<std::int64_t>(input.scans.size()) * state.iterations());
}

}  // namespace

BENCHMARK_CAPTURE(BM_Map2DLog, intel, std::string("intel"))
    ->Unit(benchmark::kSecond)
    ->Iterations(1);
BENCHMARK_CAPTURE(BM_Map2DLog, aces, std::string("aces"))->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK_CAPTURE(BM_Map2DLog, fhw, std::string("fhw"))->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK_CAPTURE(BM_Map2DLog, orebro, std::string("orebro"))
    ->Unit(benchmark::kSecond)
    ->Iterations(1);
BENCHMARK_CAPTURE(BM_Map2DLog, acapulco, std::string("acapulco"))
    ->Unit(benchmark::kSecond)
    ->Iterations(1);
BENCHMARK_CAPTURE(BM_Map2DLog, freiburg_campus, std::string("freiburg-campus"))
    ->Unit(benchmark::kSecond)
    ->Iterations(1);
