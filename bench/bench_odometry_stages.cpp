// The CTF-ICP odometry's stages one at a time, per point, on a realistic state: the map and the
// previous frame after 60 frames of dynamic-outdoor-fast, then frame 60; the whole pipeline on
// frames 60 to 209, one per iteration. Beside them, the floor the fine stage cannot beat: one hash
// probe per point, and a probe plus the plane residual's gradient (no Hessian). Compare the
// ns-per-point counters within one run.
//   build/bench/scanmatch_bench --benchmark_filter=Stage

#include <benchmark/benchmark.h>

#include <vector>

#include "scanmatch/geometry/voxel_filter.hpp"
#include "scanmatch/odometry/ctf_icp_odometry.hpp"
#include "scanmatch/registration/factors/ctf_fine.hpp"
#include "scanmatch/registration/factors/ndt.hpp"
#include "scanmatch/sim/simulator.hpp"

namespace {
using namespace scanmatch;

constexpr std::size_t kWholeFrames = 150;

struct StageState {
  OdometryConfig config;
  CtfIcpOdometry odometry{config};
  PointCloud raw;                // frame 60 as the sensor gives it
  std::vector<PointCloud> next;  // frames 60 to 79
  std::vector<double> next_times;
  PointCloud down, coarse;        // downsampled as the pipeline does (not deskewed)
  PointCloud previous;            // frame 59, downsampled, in its sensor frame
  GaussianVoxelMap previous_ndt;  // its NDT grid
  Pose previous_pose, estimate;   // frame 59's internal pose; frame 60's after registration
};

const StageState& state() {
  static const StageState* s = [] {
    auto* st = new StageState;
    sim::SimOptions o;
    o.preset = "dynamic-outdoor-fast";
    o.frames = 60 + kWholeFrames;
    const sim::Simulator sim(o);
    for (std::size_t i = 0; i < 60; ++i)
      st->odometry.register_frame(sim.frame(i), sim.frame_time(i));
    st->previous = st->odometry.last_frame();
    st->previous_pose = st->odometry.last_internal_pose();
    GaussianVoxelMapOptions ndt;
    ndt.voxel_size = st->config.ndt_resolution;
    st->previous_ndt = GaussianVoxelMap(ndt);
    st->previous_ndt.insert(st->previous);
    st->raw = sim.frame(60);
    for (std::size_t i = 60; i < 60 + kWholeFrames; ++i) {
      st->next.push_back(sim.frame(i));
      st->next_times.push_back(sim.frame_time(i));
    }
    st->down = voxel_downsample(st->raw, st->config.voxel_size);
    st->coarse = voxel_downsample(st->down, st->config.coarse_voxel_size);
    // The reference pose of frame 60: register it once (a copy of the odometry keeps the map).
    CtfIcpOdometry copy = st->odometry;
    copy.register_frame(st->raw, sim.frame_time(60));
    st->estimate = copy.last_internal_pose();
    return st;
  }();
  return *s;
}

void per_point(benchmark::State& bench, std::size_t points) {
  bench.counters["ns_per_point"] = benchmark::Counter(
      static_cast<double>(points),
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  bench.counters["points"] = static_cast<double>(points);
}

void BM_StageFloorProbe(benchmark::State& bench) {
  const StageState& s = state();
  const Pose& T = s.estimate;
  for (auto _ : bench) {
    std::size_t hits = 0;
    for (const Point& p : s.down.points)
      hits += s.odometry.map().find(T * p.cast<double>()) != nullptr;
    benchmark::DoNotOptimize(hits);
  }
  per_point(bench, s.down.size());
}

void BM_StageFloorProbeAndGradient(benchmark::State& bench) {
  const StageState& s = state();
  const Pose& T = s.estimate;
  for (auto _ : bench) {
    Vector6d gradient = Vector6d::Zero();
    for (const Point& point : s.down.points) {
      const Eigen::Vector3d y = T.linear() * point.cast<double>(), x = y + T.translation();
      const GaussianVoxel* v = s.odometry.map().find(x);
      if (v == nullptr) continue;
      const double along_normal = v->normal.dot(x - v->mean);
      gradient.head<3>() += along_normal * y.cross(v->normal);
      gradient.tail<3>() += along_normal * v->normal;
    }
    benchmark::DoNotOptimize(gradient);
  }
  per_point(bench, s.down.size());
}

CtfFineFactor fine_factor(const StageState& s) {
  return CtfFineFactor{s.down, s.odometry.map(), 1, 1.0f, false};
}
SolverOptions fine_solver(const StageState& s) {
  SolverOptions solver;
  solver.kernel.type = KernelType::kCauchy;
  solver.kernel.scale =
      s.config.fine_kernel_distance / std::sqrt(s.config.registration.ctf_epsilon);
  return solver;
}

// A first iteration: every point's voxel found by a hash probe.
void BM_StageFineLinearize(benchmark::State& bench) {
  const StageState& s = state();
  const CtfFineFactor factor = fine_factor(s);
  const SolverOptions solver = fine_solver(s);
  for (auto _ : bench) benchmark::DoNotOptimize(linearize_all(factor, s.estimate, solver));
  per_point(bench, s.down.size());
}

// A later iteration: the points' voxels remembered from the one before (VoxelHint).
void BM_StageFineLinearizeHinted(benchmark::State& bench) {
  const StageState& s = state();
  CtfFineFactor factor = fine_factor(s);
  factor.hints.resize(s.down.size());
  const SolverOptions solver = fine_solver(s);
  linearize_all(factor, s.estimate, solver);
  for (auto _ : bench) benchmark::DoNotOptimize(linearize_all(factor, s.estimate, solver));
  per_point(bench, s.down.size());
}

void coarse_linearize(benchmark::State& bench, bool hinted) {
  const StageState& s = state();
  NdtFactor factor = ndt_factor(s.coarse, s.previous_ndt, s.config.ndt_neighbours,
                                s.config.registration.ndt_outlier_ratio);
  if (hinted) factor.hints.resize(s.coarse.size());
  const Pose increment = s.previous_pose.inverse() * s.estimate;
  linearize_all(factor, increment, SolverOptions{});
  for (auto _ : bench) benchmark::DoNotOptimize(linearize_all(factor, increment, SolverOptions{}));
  per_point(bench, s.coarse.size());
}
void BM_StageCoarseLinearize(benchmark::State& bench) {
  coarse_linearize(bench, false);
}
void BM_StageCoarseLinearizeHinted(benchmark::State& bench) {
  coarse_linearize(bench, true);
}

void BM_StageMapInsert(benchmark::State& bench) {
  const StageState& s = state();
  for (auto _ : bench) {
    bench.PauseTiming();
    GaussianVoxelMap map = s.odometry.map();
    map.reserve(map.size() + s.down.size());  // the copy has no spare capacity; the map has
    bench.ResumeTiming();
    benchmark::DoNotOptimize(map.insert(s.down, s.estimate));
  }
  per_point(bench, s.down.size());
}

void BM_StageNdtGrid(benchmark::State& bench) {
  const StageState& s = state();
  GaussianVoxelMap grid = s.previous_ndt;
  for (auto _ : bench) {
    grid.clear();
    benchmark::DoNotOptimize(grid.insert(s.down));
  }
  per_point(bench, s.down.size());
}

void BM_StageDownsample(benchmark::State& bench) {
  const StageState& s = state();
  for (auto _ : bench) benchmark::DoNotOptimize(voxel_downsample(s.raw, s.config.voxel_size));
  per_point(bench, s.raw.size());
}

// Frames 60 to 209 in order, one per iteration, through a copy of the odometry made once.
void BM_StageWholeFrame(benchmark::State& bench) {
  const StageState& s = state();
  CtfIcpOdometry copy = s.odometry;
  std::size_t i = 0;
  for (auto _ : bench) {
    benchmark::DoNotOptimize(copy.register_frame(s.next[i], s.next_times[i]));
    ++i;
  }
  per_point(bench, s.down.size());
}

BENCHMARK(BM_StageFloorProbe)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_StageFloorProbeAndGradient)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_StageFineLinearize)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_StageFineLinearizeHinted)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_StageCoarseLinearize)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_StageCoarseLinearizeHinted)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_StageMapInsert)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_StageNdtGrid)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_StageDownsample)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_StageWholeFrame)->Unit(benchmark::kMicrosecond)->Iterations(kWholeFrames);

}  // namespace
