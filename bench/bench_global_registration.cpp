// Global registration (no initial guess) from 12 yaws in [-165, 170] deg and a 10 m offset in a
// different direction each: how many are accepted, how many land within 5 cm and 0.5 deg of the
// reference, the worst error and the time per pair. Pairs: ../shared's hdl32_pair and car_pair
// (errors against their reference transforms) and simulated campus-os1 frames 40 and 45 (truth);
// the source's sensor position either known (moved with it) or assumed at the origin, as the CLI
// does for a file.
//   build/bench/scanmatch_bench --benchmark_filter=GlobalRegistration

#include <benchmark/benchmark.h>

#include <chrono>

#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

#include "scanmatch/io/cloud_io.hpp"
#include "scanmatch/registration/global_registration.hpp"
#include "scanmatch/sim/simulator.hpp"

namespace {
using namespace scanmatch;

struct GlobalPair {
  PointCloud source, target;
  Pose truth;  // T_target_source
};

Pose read_matrix(std::istream& in) {
  Eigen::Matrix4d M;
  for (int i = 0; i < 16; ++i) in >> M(i / 4, i % 4);
  return from_matrix(M);
}

std::string shared_3d(const std::string& name) {
  const auto p =
      std::filesystem::path(SCANMATCH_SOURCE_DIR) / ".." / "shared" / "data" / "3d" / name;
  return std::filesystem::exists(p) ? p.string() : std::string();
}

std::optional<GlobalPair> load_pair(int which) {
  if (which == 2) {
    sim::SimOptions o;
    o.preset = "campus-os1";
    o.frames = 46;
    o.motion_distortion = false;
    const sim::Simulator s(o);
    return GlobalPair{s.frame(45), s.frame(40), s.pose(40).inverse() * s.pose(45)};
  }
  if (which == 0) {
    const std::string d = shared_3d("hdl32_pair");
    if (d.empty()) return std::nullopt;
    std::ifstream in(d + "/T_target_source.txt");
    return GlobalPair{read_cloud(d + "/source.ply"), read_cloud(d + "/target.ply"),
                      read_matrix(in)};
  }
  const std::string d = shared_3d("car_pair");
  if (d.empty()) return std::nullopt;
  std::ifstream list(d + "/carCloudList.csv");
  std::string line;
  while (std::getline(list, line)) {
    if (line.rfind("car_cloud401.csv", 0) != 0) continue;
    std::string values = line.substr(line.find(',') + 1);
    for (char& c : values)
      if (c == ',') c = ' ';
    std::istringstream row(values);
    return GlobalPair{read_cloud(d + "/car_cloud401.csv"), read_cloud(d + "/car_cloud400.csv"),
                      read_matrix(row)};
  }
  return std::nullopt;
}

const char* const kPairNames[] = {"hdl32_pair", "car_pair", "campus-os1 40/45"};

void BM_GlobalRegistration(benchmark::State& state) {
  const int which = static_cast<int>(state.range(0));
  const bool viewpoint_known = state.range(1) != 0;
  const std::optional<GlobalPair> pair = load_pair(which);
  if (!pair) {
    state.SkipWithError("../shared/data/3d pair not present");
    for (auto _ : state) {
    }
    return;
  }
  int accepted = 0, within = 0, runs = 0;
  double worst_cm = 0, worst_deg = 0, total_ms = 0, inliers = 0, worst_ambiguity = 0;
  for (auto _ : state) {
    for (int k = 0; k < 12; ++k) {
      const double yaw = (-165.0 + 30.0 * k + (k % 3) * 5.0) * M_PI / 180;
      const double direction = (17.0 + 97.0 * k) * M_PI / 180;
      const Pose P = from_xyz_rpy(10 * std::cos(direction), 10 * std::sin(direction), 0, 0, 0, yaw);
      PointCloud source = pair->source;
      for (Point& p : source.points) p = (P * p.cast<double>()).cast<float>();
      GlobalRegistrationOptions o;
      if (viewpoint_known) o.source_viewpoint = P.translation();
      const auto start = std::chrono::steady_clock::now();
      const GlobalRegistrationResult r = register_global(source, pair->target, o);
      total_ms +=
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
              .count();
      ++runs;
      if (!r.success) continue;
      const Pose error = (pair->truth * P.inverse()).inverse() * r.transform;
      const double cm = 100 * error.translation().norm(),
                   deg = rotation_angle(error) * kDegreesPerRadian;
      ++accepted;
      within += cm < 5 && deg < 0.5;
      worst_cm = std::max(worst_cm, cm);
      worst_deg = std::max(worst_deg, deg);
      inliers += static_cast<double>(r.inliers);
      worst_ambiguity = std::max(worst_ambiguity, r.ambiguity);
    }
  }
  state.SetLabel(std::string(kPairNames[which]) +
                 (viewpoint_known ? ", viewpoint known" : ", viewpoint at the origin"));
  state.counters["accepted"] = accepted;
  state.counters["within_5cm_0.5deg"] = within;
  state.counters["worst_cm"] = worst_cm;
  state.counters["worst_deg"] = worst_deg;
  state.counters["mean_inliers"] = accepted > 0 ? inliers / accepted : 0.0;
  state.counters["worst_ambiguity"] = worst_ambiguity;
  state.counters["ms_per_pair"] = runs > 0 ? total_ms / runs : 0.0;
}
BENCHMARK(BM_GlobalRegistration)
    ->ArgsProduct({{0, 1, 2}, {1, 0}})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);

}  // namespace
