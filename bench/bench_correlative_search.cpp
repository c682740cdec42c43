// Correlative search micro-benchmarks on simulated office scans (sim:corridor-2d, no shared data
// needed): the odometry's search (+-1.3 m, +-45 deg, 5 cm), its wide search (+-90 deg), and a
// loop verification's search (+-2 m, +-30 deg, 10 cm) of a scan against one 20 scans away, with
// and without the minimum score that lets a search of a place that does not fit end early.
//   build/bench/scanmatch_bench --benchmark_filter=CorrelativeSearch

#include <benchmark/benchmark.h>

#include "scanmatch/registration/planar/correlative_search.hpp"
#include "scanmatch/run/map2d_run.hpp"

namespace {
using namespace scanmatch;

const std::vector<Scan2D>& scans() {
  static const std::vector<Scan2D> out = [] {
    SequenceOptions o;
    o.simulator.motion_distortion = false;
    const Scans2D input = load_scans_2d("sim:corridor-2d", o, 60);
    std::vector<Scan2D> s;
    for (const LaserScan2D& scan : input.scans) s.push_back(scan_from_laser(scan, 0.05));
    return s;
  }();
  return out;
}

// Pairs `gap` scans apart from the identity, over the first 40 scans.
void BM_CorrelativeSearch(benchmark::State& state, std::size_t gap, double window, double angle_deg,
                          double resolution, double min_score) {
  const std::vector<Scan2D>& s = scans();
  std::size_t found = 0, searches = 0;
  for (auto _ : state)
    for (std::size_t i = 0; i + gap < s.size() && i < 40; i += 4) {
      const CorrelativeMatch m =
          correlative_match(s[i + gap], s[i], Pose2::Identity(), window, angle_deg * M_PI / 180,
                            resolution, 1.0, min_score);
      found += m.found;
      ++searches;
    }
  benchmark::DoNotOptimize(found);
  state.SetItemsProcessed(static_cast<std::int64_t>(searches));
}
BENCHMARK_CAPTURE(BM_CorrelativeSearch, odometry, 1, 1.3, 45.0, 0.05, 0.0)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_CorrelativeSearch, odometry_wide, 1, 1.3, 90.0, 0.05, 0.0)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_CorrelativeSearch, loop_candidate, 20, 2.0, 30.0, 0.1, 0.0)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_CorrelativeSearch, loop_candidate_min_score, 20, 2.0, 30.0, 0.1, 0.5)
    ->Unit(benchmark::kMillisecond);

}  // namespace
