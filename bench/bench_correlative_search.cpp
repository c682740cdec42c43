// Correlative search micro-benchmarks on simulated office scans (sim:corridor-2d, no shared data
// needed): the odometry's search (+-1.3 m, +-45 deg, 5 cm), its wide search (+-90 deg), and a
// loop verification's search (+-2 m, +-30 deg, 10 cm) of a scan against one 20 scans away, with
// and without the minimum score that lets a search of a place that does not fit end early; and the
// odometry's four searches of a step onto one grid, as CorrelativeSearches or separately.
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

// The odometry's four searches of one step (narrow +-45 deg, wide +-90 deg, the whole turn, long
// 3.5 x 1.3 m), each from the best score so far, onto one 5 cm grid: as CorrelativeSearches (each
// skips the windows searched before it) or as four separate searches. Consecutive scans.
void BM_OdometrySearches(benchmark::State& state, bool together) {
  const std::vector<Scan2D>& s = scans();
  std::vector<CorrelativeGrid> grids;
  for (std::size_t i = 0; i + 1 < s.size() && i < 40; i += 4) grids.emplace_back(s[i], 0.05, 1.0);
  const double degree = M_PI / 180;
  const std::vector<std::pair<Eigen::Vector2d, double>> windows = {
      {Eigen::Vector2d(1.3, 1.3), 45 * degree},
      {Eigen::Vector2d(1.3, 1.3), 90 * degree},
      {Eigen::Vector2d(1.3, 1.3), 180 * degree},
      {Eigen::Vector2d(3.5, 1.3), 90 * degree}};
  double total = 0.0;
  for (auto _ : state)
    for (std::size_t k = 0; k < grids.size(); ++k) {
      const Scan2D& current = s[4 * k + 1];
      CorrelativeSearches searches(current, grids[k], Pose2::Identity());
      double score = 0.0;
      for (const auto& [window, angle] : windows) {
        const CorrelativeMatch m =
            together
                ? searches.match(window, angle, score)
                : correlative_match(current, grids[k], Pose2::Identity(), window, angle, score);
        if (m.found) score = m.score;
      }
      total += score;
    }
  benchmark::DoNotOptimize(total);
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * grids.size()));
}
BENCHMARK_CAPTURE(BM_OdometrySearches, together, true)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_OdometrySearches, separately, false)->Unit(benchmark::kMillisecond);

}  // namespace
