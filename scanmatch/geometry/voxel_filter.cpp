#include "scanmatch/geometry/voxel_filter.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "scanmatch/core/error.hpp"
#include "scanmatch/geometry/voxel_hash.hpp"
#include "scanmatch/geometry/voxel_key.hpp"

namespace scanmatch {
namespace {

struct Accumulator {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  std::uint32_t count = 0;
  std::uint32_t first = 0;  // index of the first point met in this voxel
};

// Per-thread scratch reused across calls: fresh multi-megabyte buffers on every frame cost more in
// page faults than the downsampling itself.
struct Workspace {
  std::vector<std::uint32_t> voxel_of_point;
  VoxelHashTable<Accumulator> voxels;
};

// The table is sized for at least this many voxels (4096 slots of 16 bytes): small frames never
// grow it, and it stays in L2 cache.
constexpr std::size_t kMinimumExpectedVoxels = 2048;

constexpr std::uint32_t kSkipped = std::numeric_limits<std::uint32_t>::max();

}  // namespace

PointCloud voxel_downsample(const PointCloud& cloud, double voxel_size, VoxelReduction reduction) {
  if (!(voxel_size > 0.0) || !std::isfinite(voxel_size))
    fail("voxel_downsample",
         "voxel size must be a positive number, got " + std::to_string(voxel_size));
  const std::size_t n = cloud.size();
  if (n >= kSkipped) fail("voxel_downsample", "too many points for 32-bit indices");
  const float inv = static_cast<float>(1.0 / voxel_size);
  constexpr float kLimit = 2.0e9f;

  thread_local Workspace workspace;
  std::vector<std::uint32_t>& voxel_of_point = workspace.voxel_of_point;
  VoxelHashTable<Accumulator>& table = workspace.voxels;
  voxel_of_point.resize(n);
  // The previous call's voxel count is the best guess for this one (consecutive frames).
  table.reset(std::max(table.size(), kMinimumExpectedVoxels));
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3f s = cloud.points[i] * inv;
    if (!s.allFinite()) {
      voxel_of_point[i] = kSkipped;
      continue;
    }
    if (std::abs(s.x()) > kLimit || std::abs(s.y()) > kLimit || std::abs(s.z()) > kLimit)
      fail("voxel_downsample", "point " + std::to_string(i) +
                                   " is too far from the origin for voxel size " +
                                   std::to_string(voxel_size));
    const auto [v, inserted] = table.find_or_insert(voxel_key_scaled(s));
    Accumulator& voxel = table.value(v);
    if (inserted) voxel.first = static_cast<std::uint32_t>(i);
    voxel.sum += cloud.points[i].cast<double>();
    ++voxel.count;
    voxel_of_point[i] = static_cast<std::uint32_t>(v);
  }
  const std::vector<Accumulator>& voxels = table.values();

  PointCloud out;
  const std::size_t m = voxels.size();
  if (reduction == VoxelReduction::kCentroid) {
    out.points.resize(m);
    if (cloud.has_intensity()) out.intensity.resize(m);
    if (cloud.has_ring()) out.ring.resize(m);
    if (cloud.has_time()) out.time.resize(m);
    for (std::size_t v = 0; v < m; ++v) {
      out.points[v] = (voxels[v].sum / voxels[v].count).cast<float>();
      if (cloud.has_ring()) out.ring[v] = cloud.ring[voxels[v].first];
    }
    // Scalar fields are averaged in a separate pass, paid only when the field exists.
    const auto average_field = [&](const std::vector<float>& in, std::vector<float>& field) {
      std::vector<double> sums(m, 0.0);
      for (std::size_t i = 0; i < n; ++i)
        if (voxel_of_point[i] != kSkipped) sums[voxel_of_point[i]] += in[i];
      for (std::size_t v = 0; v < m; ++v) field[v] = static_cast<float>(sums[v] / voxels[v].count);
    };
    if (cloud.has_intensity()) average_field(cloud.intensity, out.intensity);
    if (cloud.has_time()) average_field(cloud.time, out.time);
    return out;
  }

  // Nearest to centroid: a second pass keeps, per voxel, the point closest to the mean.
  std::vector<float> best_distance(m, std::numeric_limits<float>::max());
  std::vector<std::uint32_t> best_point(m, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t v = voxel_of_point[i];
    if (v == kSkipped) continue;
    const Eigen::Vector3f mean = (voxels[v].sum / voxels[v].count).cast<float>();
    const float d = (cloud.points[i] - mean).squaredNorm();
    if (d < best_distance[v]) {
      best_distance[v] = d;
      best_point[v] = static_cast<std::uint32_t>(i);
    }
  }
  return select(cloud, std::vector<std::size_t>(best_point.begin(), best_point.end()));
}

PointCloud thin_to_points(PointCloud cloud, double voxel, std::size_t max_points) {
  if (max_points == 0 || cloud.size() <= max_points || !(voxel > 0.0)) return cloud;
  const double scale =
      std::sqrt(static_cast<double>(cloud.size()) / static_cast<double>(max_points));
  return voxel_downsample(cloud, voxel * scale);
}

namespace {
template <typename Keep>
PointCloud filter_points(const PointCloud& cloud, Keep keep) {
  std::vector<std::size_t> kept;
  kept.reserve(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i)
    if (keep(cloud.points[i])) kept.push_back(i);
  return select(cloud, kept);
}
}  // namespace

PointCloud crop_range(const PointCloud& cloud, double min_range, double max_range) {
  const double min2 = min_range * min_range, max2 = max_range * max_range;
  return filter_points(cloud, [&](const Point& p) {
    const double r2 = p.cast<double>().squaredNorm();
    return r2 >= min2 && r2 <= max2;
  });
}

PointCloud crop_box(const PointCloud& cloud, const Eigen::AlignedBox3f& box, bool keep_inside) {
  return filter_points(cloud, [&](const Point& p) { return box.contains(p) == keep_inside; });
}

std::size_t remove_non_finite(PointCloud& cloud) {
  const std::size_t before = cloud.size();
  if (std::all_of(cloud.points.begin(), cloud.points.end(),
                  [](const Point& p) { return p.allFinite(); }))
    return 0;
  PointCloud kept = filter_points(cloud, [](const Point& p) { return p.allFinite(); });
  if (kept.size() == before) return 0;
  cloud = std::move(kept);
  return before - cloud.size();
}

}  // namespace scanmatch
