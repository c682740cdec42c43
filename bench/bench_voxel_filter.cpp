#include <benchmark/benchmark.h>

#include <filesystem>
#include <random>

#include "scanmatch/geometry/voxel_filter.hpp"
#include "scanmatch/io/cloud_io.hpp"

namespace {
// A spinning-LiDAR-like frame: 64 rings x 1875 azimuth steps (120,000 points, HDL-64E-like),
// hitting a ground plane 1.7 m below the sensor or walls of a street 8 to 40 m away.
scanmatch::PointCloud lidar_like_cloud() {
  std::mt19937 rng(7);
  std::normal_distribution<float> noise(0.0f, 0.02f);
  scanmatch::PointCloud cloud;
  cloud.points.reserve(120000);
  for (int azimuth_step = 0; azimuth_step < 1875; ++azimuth_step) {
    const float azimuth = static_cast<float>(azimuth_step) * 2.0f * 3.14159265f / 1875.0f;
    const float wall_distance = 8.0f + 32.0f * std::abs(std::sin(3.0f * azimuth));
    for (int ring = 0; ring < 64; ++ring) {
      const float elevation =
          (-24.9f + 26.9f * static_cast<float>(ring) / 63.0f) * 3.14159265f / 180.0f;
      const Eigen::Vector3f dir(std::cos(elevation) * std::cos(azimuth),
                                std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
      float range = wall_distance / std::max(0.05f, std::cos(elevation));
      if (dir.z() < 0.0f) range = std::min(range, 1.7f / -dir.z());
      cloud.points.push_back(dir * (range + noise(rng)));
      cloud.intensity.push_back(1.0f);
    }
  }
  return cloud;
}
}  // namespace

static void BM_VoxelDownsample120k(benchmark::State& state) {
  const auto cloud = lidar_like_cloud();
  const double voxel = static_cast<double>(state.range(0)) / 100.0;
  const auto reduction = state.range(1) == 0 ? scanmatch::VoxelReduction::kCentroid
                                             : scanmatch::VoxelReduction::kNearestToCentroid;
  std::size_t kept = 0;
  for (auto _ : state) {
    auto out = scanmatch::voxel_downsample(cloud, voxel, reduction);
    kept = out.size();
    benchmark::DoNotOptimize(out.points.data());
  }
  state.counters["points_out"] = static_cast<double>(kept);
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * cloud.size()));
}
BENCHMARK(BM_VoxelDownsample120k)
    ->ArgsProduct({{5, 20, 50, 100}, {0, 1}})
    ->ArgNames({"voxel_cm", "nearest"})
    ->Unit(benchmark::kMillisecond);

// Calibration: one pass summing the same 120,000 points, the floor of any downsampling.
static void BM_SumPoints120k(benchmark::State& state) {
  const auto cloud = lidar_like_cloud();
  for (auto _ : state) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const auto& p : cloud.points) sum += p.cast<double>();
    benchmark::DoNotOptimize(sum);
  }
}
BENCHMARK(BM_SumPoints120k)->Unit(benchmark::kMillisecond);

// A recorded HDL-64E scan (../shared/data/3d/kitti_raw_0027_first60, scan 0: 120k points in the
// sensor's own order), as the odometry filters it at 0.25 m. Its points come in firing order, not
// the synthetic cloud's: the hash table is probed in another pattern.
static void BM_VoxelDownsampleKittiScan(benchmark::State& state) {
  const std::filesystem::path path = std::filesystem::path(SCANMATCH_SOURCE_DIR) / ".." / "shared" /
                                     "data" / "3d" / "kitti_raw_0027_first60" / "velodyne" /
                                     "0000000000.bin";
  if (!std::filesystem::exists(path)) {
    state.SkipWithError("../shared/data/3d/kitti_raw_0027_first60 not present");
    return;
  }
  const scanmatch::PointCloud cloud = scanmatch::read_cloud(path.string());
  const double voxel = static_cast<double>(state.range(0)) / 100.0;
  std::size_t kept = 0;
  for (auto _ : state) {
    auto out = scanmatch::voxel_downsample(cloud, voxel);
    kept = out.size();
    benchmark::DoNotOptimize(out.points.data());
  }
  state.counters["points_out"] = static_cast<double>(kept);
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * cloud.size()));
}
BENCHMARK(BM_VoxelDownsampleKittiScan)
    ->Arg(25)
    ->Arg(70)
    ->ArgName("voxel_cm")
    ->Unit(benchmark::kMillisecond);
