// Registration benchmarks: each method single-threaded on one simulated pair per sensor (time,
// iterations, per-iteration cost, accuracy against ground truth), and the convergence basin of
// each method (success rate over random initial errors of growing size).
//   build/bench/scanmatch_bench --benchmark_filter=Register
//   build/bench/scanmatch_bench --benchmark_filter=Basin

#include <benchmark/benchmark.h>

#include <map>
#include <random>

#include "scanmatch/geometry/voxel_filter.hpp"
#include "scanmatch/registration/methods.hpp"
#include "scanmatch/sim/simulator.hpp"

namespace {
using namespace scanmatch;

struct BenchPair {
  PointCloud source, target;          // downsampled to 0.25 m
  PointCloud raw_source, raw_target;  // full frames (the loam methods need the ring structure)
  Pose truth, guess;
};

// Frames 40 and 41 of a preset, downsampled to 0.25 m, without motion distortion.
const BenchPair& pair_for(const std::string& preset) {
  static std::map<std::string, BenchPair> cache;
  auto it = cache.find(preset);
  if (it != cache.end()) return it->second;
  sim::SimOptions o;
  o.preset = preset;
  o.frames = 42;
  o.motion_distortion = false;
  const sim::Simulator s(o);
  PointCloud source = s.frame(41), target = s.frame(40);
  BenchPair p{voxel_downsample(source, 0.25),
              voxel_downsample(target, 0.25),
              std::move(source),
              std::move(target),
              s.pose(40).inverse() * s.pose(41),
              s.pose(39).inverse() * s.pose(40)};
  return cache.emplace(preset, std::move(p)).first->second;
}

const std::vector<std::string> kMethods = {
    "icp", "icp-gn", "point-to-plane", "point-to-line", "gicp", "vgicp", "ndt", "ctf-fine", "loam"};
bool uses_raw(const std::string& method) {
  return method.rfind("loam", 0) == 0;
}
const std::vector<std::string> kPresets = {"campus-os1", "dynamic-outdoor"};

void BM_Register(benchmark::State& state) {
  const std::string& method = kMethods[static_cast<std::size_t>(state.range(0))];
  const BenchPair& pair = pair_for(kPresets[static_cast<std::size_t>(state.range(1))]);
  RegistrationOptions o;
  o.method = method;
  RegistrationResult r;
  const PointCloud& source = uses_raw(method) ? pair.raw_source : pair.source;
  const PointCloud& target = uses_raw(method) ? pair.raw_target : pair.target;
  for (auto _ : state) r = register_clouds(source, target, o, pair.guess);
  const Pose error = pair.truth.inverse() * r.transform;
  state.SetLabel(method + " " + kPresets[static_cast<std::size_t>(state.range(1))]);
  state.counters["iterations"] = r.iterations;
  state.counters["points"] = static_cast<double>(source.size());
  state.counters["error_cm"] = 100.0 * error.translation().norm();
  state.counters["error_deg"] = rotation_angle(error) * 180.0 / M_PI;
  // Points linearised per second (all iterations): the per-iteration throughput.
  state.counters["point_iterations_per_s"] =
      benchmark::Counter(static_cast<double>(pair.source.size()) * r.iterations,
                         benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_Register)
    ->ArgsProduct({benchmark::CreateDenseRange(0, static_cast<int>(kMethods.size()) - 1, 1),
                   {0, 1}})
    ->Unit(benchmark::kMillisecond);

// Success rate (within 5 cm and 0.5 deg of the truth) over 20 random initial errors of a given
// size: translation `metres` in a random direction and rotation metres * 10 deg about a random
// axis.
void BM_Basin(benchmark::State& state) {
  const std::string& method = kMethods[static_cast<std::size_t>(state.range(0))];
  const double metres = static_cast<double>(state.range(1)) / 100.0;
  const BenchPair& pair = pair_for("dynamic-outdoor");
  RegistrationOptions o;
  o.method = method;
  o.max_correspondence_distance = std::max(1.0, 2.0 * metres);
  o.solver.max_iterations = 60;
  std::mt19937 rng(11);
  std::normal_distribution<double> n(0.0, 1.0);
  int successes = 0, trials = 0;
  for (auto _ : state) {
    for (int t = 0; t < 20; ++t) {
      const Eigen::Vector3d dir = Eigen::Vector3d(n(rng), n(rng), 0.3 * n(rng)).normalized();
      const Eigen::Vector3d axis = Eigen::Vector3d(0.2 * n(rng), 0.2 * n(rng), n(rng)).normalized();
      Vector6d xi;
      xi.head<3>() = axis * (metres * 10.0 * M_PI / 180.0);
      xi.tail<3>() = dir * metres;
      const Pose initial = pair.truth * se3_exp(xi);
      const RegistrationResult r =
          uses_raw(method) ? register_clouds(pair.raw_source, pair.raw_target, o, initial)
                           : register_clouds(pair.source, pair.target, o, initial);
      const Pose error = pair.truth.inverse() * r.transform;
      successes += error.translation().norm() < 0.05 && rotation_angle(error) * 180 / M_PI < 0.5;
      ++trials;
    }
  }
  state.SetLabel(method + " initial error " + std::to_string(metres).substr(0, 4) + " m");
  state.counters["success_rate"] = static_cast<double>(successes) / trials;
}
BENCHMARK(BM_Basin)
    ->ArgsProduct({benchmark::CreateDenseRange(0, static_cast<int>(kMethods.size()) - 1, 1),
                   {25, 50, 100, 200}})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);

}  // namespace
