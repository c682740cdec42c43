#include "scanmatch/geometry/voxel_filter.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "scanmatch/core/error.hpp"
#include "scanmatch/geometry/voxel_key.hpp"

namespace scanmatch {
namespace {

// Open addressing with linear probing over 16-byte entries (key and dense voxel index side by
// side). The table is sized by the number of voxels, not points, and grows at half load, so for a
// typical frame it stays in L2 cache.
class VoxelSlots {
 public:
  static constexpr std::uint32_t kEmpty = std::numeric_limits<std::uint32_t>::max();

  /// Empties the table, sized for about `expected` voxels (it still grows when needed); keeps
  /// the allocation between calls, but never a table much larger than the work at hand.
  void reset(std::size_t expected) {
    std::size_t capacity = kInitialCapacity;
    while (capacity < 2 * expected) capacity <<= 1;
    entries_.assign(capacity, Entry{{0, 0, 0}, kEmpty});
    size_ = 0;
  }

  /// Returns the voxel's dense index, creating it (index = count so far) when new.
  std::uint32_t find_or_insert(const VoxelKey& key) {
    const std::size_t mask = entries_.size() - 1;
    std::size_t i = VoxelKeyHash{}(key)&mask;
    while (true) {
      Entry& e = entries_[i];
      if (e.index == kEmpty) {
        e.key = key;
        e.index = size_++;
        if (2 * size_ > entries_.size()) grow();
        return size_ - 1;
      }
      if (e.key == key) return e.index;
      i = (i + 1) & mask;
    }
  }

 private:
  struct Entry {
    VoxelKey key;
    std::uint32_t index;
  };
  static constexpr std::size_t kInitialCapacity = 4096;

  void grow() {
    std::vector<Entry> old(2 * entries_.size(), Entry{{0, 0, 0}, kEmpty});
    old.swap(entries_);
    const std::size_t mask = entries_.size() - 1;
    for (const Entry& e : old) {
      if (e.index == kEmpty) continue;
      std::size_t i = VoxelKeyHash{}(e.key) & mask;
      while (entries_[i].index != kEmpty) i = (i + 1) & mask;
      entries_[i] = e;
    }
  }

  std::vector<Entry> entries_;
  std::uint32_t size_ = 0;
};

struct Accumulator {
  Eigen::Vector3d sum;
  std::uint32_t count;
  std::uint32_t first;  // index of the first point met in this voxel
};

// Per-thread scratch reused across calls: fresh multi-megabyte buffers on every frame cost more in
// page faults than the downsampling itself.
struct Workspace {
  std::vector<std::uint32_t> voxel_of_point;
  VoxelSlots slots;
  std::vector<Accumulator> voxels;
};

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
  std::vector<Accumulator>& voxels = workspace.voxels;
  VoxelSlots& slots = workspace.slots;
  voxel_of_point.resize(n);
  // The previous call's voxel count is the best guess for this one (consecutive frames).
  slots.reset(voxels.size());
  voxels.clear();
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
    const std::uint32_t v = slots.find_or_insert(voxel_key_scaled(s));
    if (v == voxels.size())
      voxels.push_back(Accumulator{Eigen::Vector3d::Zero(), 0, static_cast<std::uint32_t>(i)});
    voxels[v].sum += cloud.points[i].cast<double>();
    ++voxels[v].count;
    voxel_of_point[i] = v;
  }

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
