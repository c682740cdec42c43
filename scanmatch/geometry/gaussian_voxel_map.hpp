#pragma once
// The one voxel map of Gaussians (count, mean, covariance per voxel, addressed by a hash of the
// integer voxel coordinate). It serves NDT, VGICP and the CTF-ICP fine stage, and is the CTF-ICP
// global map: points accumulate per voxel and are merged into its Gaussian only once
// `merge_threshold` new points are pending (docs/methods.md section 1 step 4).

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/core/se3.hpp"
#include "scanmatch/geometry/voxel_hash.hpp"
#include "scanmatch/geometry/voxel_key.hpp"

namespace scanmatch {

/// 64-byte aligned so that what the CTF-ICP fine stage reads per point (count, flatness, mean,
/// normal) shares one cache line.
struct alignas(64) GaussianVoxel {
  // Hot: what registration reads per point. flatness, normal and the distributions are derived
  // from the covariance after each merge that leaves count >= the map's min_points (below it the
  // voxel is not used and they keep their defaults).
  std::uint32_t count = 0;  ///< points merged into the Gaussian
  /// Smallest over middle eigenvalue: near 0 for a plane, up to 1 for a blob or a corner.
  float flatness = 1.0f;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< smallest eigenvector
  // Next (the lines an insert touches after the hot one): the points waiting to be merged, sums
  // relative to the voxel's corner for precision.
  std::uint32_t pending = 0;
  std::uint64_t last_insert = 0;  ///< which insert() call last touched the voxel
  Eigen::Vector3d pending_sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d pending_outer = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  ///< population covariance
  /// Only when the map's options ask for them (NDT, VGICP); eigenvalues clamped to >= 1e-3 of
  /// the largest.
  Eigen::Matrix3d regularized_information = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d regularized_covariance = Eigen::Matrix3d::Identity();
};

/// The CTF-ICP planar information (Q diag(1/eps, 1, 1) Q^T, the covariance's eigenvalues
/// normalised to (eps, 1, 1)), which is I + (1/eps - 1) n n^T for the voxel normal n.
inline Eigen::Matrix3d planar_information(const GaussianVoxel& voxel, double epsilon) {
  return Eigen::Matrix3d::Identity() +
         (1.0 / epsilon - 1.0) * voxel.normal * voxel.normal.transpose();
}

/// Where a point's voxel was found last (GaussianVoxelMap::find with a hint).
struct VoxelHint {
  static constexpr std::int32_t kUnknown = -2;
  VoxelKey key;
  std::int32_t slot = kUnknown;  ///< position in the map's voxels(), -1: no voxel
};

struct GaussianVoxelMapOptions {
  double voxel_size = 1.0;            ///< m
  std::uint32_t merge_threshold = 1;  ///< pending points needed before a merge (CTF-ICP: 5)
  std::uint32_t min_points = 5;       ///< a voxel is used for registration from this many points
  double planar_epsilon = 1e-6;       ///< smallest eigenvalue of the planar covariance (CTF: 1e-6)
  /// A voxel whose Gaussian holds this many points takes no more (0: no limit). Mature voxels then
  /// stay fixed, so small registration errors of later frames cannot drag the map along.
  std::uint32_t max_points = 0;
  /// Cache each voxel's regularised covariance and information (NDT, VGICP read them); the CTF-ICP
  /// fine stage reads only the mean and normal, and its map skips them.
  bool distributions = true;
};

class GaussianVoxelMap {
 public:
  explicit GaussianVoxelMap(const GaussianVoxelMapOptions& options = {});

  /// Adds the cloud's points moved by `pose`; merges every voxel whose pending points reached the
  /// threshold. Returns the number of voxels merged.
  std::size_t insert(const PointCloud& cloud, const Pose& pose = Pose::Identity());
  /// Merges every voxel's pending points regardless of the threshold.
  void flush();
  /// Removes every voxel but keeps the allocations (a map rebuilt every frame).
  void clear();
  /// Room for this many voxels without reallocating.
  void reserve(std::size_t voxels);
  /// Drops voxels whose mean is farther than `radius` from `center` (bounded map memory).
  std::size_t remove_far(const Eigen::Vector3d& center, double radius);

  /// floor(p / voxel size); by a product with the inverse when that is exact (sizes that are
  /// powers of two, as the odometry's 0.5 m and 1 m): the same keys without three divisions.
  VoxelKey index_of(const Eigen::Vector3d& p) const {
    if (exact_inverse_) return voxel_key_scaled(Eigen::Vector3d(p * inverse_size_));
    return voxel_key(p, options_.voxel_size);
  }
  /// The usable voxel (count >= min_points) containing p, or nullptr.
  const GaussianVoxel* find(const Eigen::Vector3d& p) const {
    const std::int32_t slot = voxels_.find(index_of(p));
    if (slot < 0) return nullptr;
    const GaussianVoxel& v = voxels_.value(static_cast<std::size_t>(slot));
    return v.count >= options_.min_points ? &v : nullptr;
  }
  /// The same, remembering p's voxel in `hint`: a point that stays in its voxel between the
  /// iterations of one registration skips the hash probe. The map must not change while hints
  /// are in use.
  const GaussianVoxel* find(const Eigen::Vector3d& p, VoxelHint& hint) const {
    const VoxelKey key = index_of(p);
    if (hint.slot == VoxelHint::kUnknown || !(hint.key == key))
      hint = VoxelHint{key, voxels_.find(key)};
    if (hint.slot < 0) return nullptr;
    const GaussianVoxel& v = voxels_.value(static_cast<std::size_t>(hint.slot));
    return v.count >= options_.min_points ? &v : nullptr;
  }
  /// For a loop over points i with hints (find(position_of(i), hints[i])): at point i, resolves
  /// the hint of point i + kNear and starts loading its voxel, and starts the hash probe of point
  /// i + kFar, so that the loop's memory reads overlap instead of waiting in turn. Results do not
  /// change. `position_of(j)` is point j's position in the map frame.
  template <typename PositionOf>
  void prefetch_ahead(std::size_t i, std::size_t end, std::span<VoxelHint> hints,
                      PositionOf&& position_of) const {
    constexpr std::size_t kNear = 8, kFar = 16;
    if (voxels_.empty()) return;
    if (i + kFar < end && hints[i + kFar].slot == VoxelHint::kUnknown)
      voxels_.prefetch(index_of(position_of(i + kFar)));
    if (i + kNear < end) {
      VoxelHint& ahead = hints[i + kNear];
      if (ahead.slot == VoxelHint::kUnknown) find(position_of(i + kNear), ahead);
      if (ahead.slot >= 0) __builtin_prefetch(&voxels_.value(static_cast<std::size_t>(ahead.slot)));
    }
  }
  /// Calls f(voxel) for the usable voxels among p's voxel and its 6 (neighbours = 7) or 26
  /// (neighbours = 27) neighbours; neighbours = 1 is p's voxel only.
  template <typename F>
  void for_each_neighbour(const Eigen::Vector3d& p, int neighbours, F&& f) const {
    const GaussianVoxel* found[27];
    const int count = gather_neighbours(p, neighbours, found);
    for (int k = 0; k < count; ++k) f(*found[k]);
  }

  /// gather_neighbours, or with a hint (one voxel per point only) the hinted find.
  int gather_neighbours(const Eigen::Vector3d& p, int neighbours, const GaussianVoxel** out,
                        VoxelHint* hint) const {
    if (hint == nullptr) return gather_neighbours(p, neighbours, out);
    out[0] = find(p, *hint);
    return out[0] != nullptr;
  }

  /// The same voxels as for_each_neighbour, written to `out` (room for `neighbours`, at most 27);
  /// returns how many. For hot loops: a plain loop over them inlines where a callback may not.
  int gather_neighbours(const Eigen::Vector3d& p, int neighbours, const GaussianVoxel** out) const {
    const VoxelKey c = index_of(p);
    int found = 0;
    for (const auto& o : offsets(neighbours)) {
      const std::int32_t slot = voxels_.find(VoxelKey{c.x + o[0], c.y + o[1], c.z + o[2]});
      if (slot < 0) continue;
      const GaussianVoxel& v = voxels_.value(static_cast<std::size_t>(slot));
      if (v.count >= options_.min_points) out[found++] = &v;
    }
    return found;
  }

  std::size_t size() const { return voxels_.size(); }
  const GaussianVoxelMapOptions& options() const { return options_; }
  /// Every voxel (usable or not) and its index, in parallel, in no particular order.
  const std::vector<GaussianVoxel>& voxels() const { return voxels_.values(); }
  const std::vector<VoxelKey>& indices() const { return voxels_.keys(); }

  /// The merge of docs/methods.md: (m, mu1, C1) + (n, mu2, C2) with the outer-product cross term.
  static void merge(GaussianVoxel& voxel, std::uint32_t n, const Eigen::Vector3d& mean,
                    const Eigen::Matrix3d& covariance);

 private:
  /// Constant tables (no initialisation guard on the hot path), in the order the sums use.
  static std::span<const std::array<int, 3>> offsets(int neighbours) {
    static constexpr std::array<std::array<int, 3>, 1> kOne{{{0, 0, 0}}};
    static constexpr std::array<std::array<int, 3>, 7> kSeven{
        {{0, 0, 0}, {1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}}};
    static constexpr std::array<std::array<int, 3>, 27> kAll = [] {
      std::array<std::array<int, 3>, 27> all{};
      std::size_t i = 0;
      for (int x = -1; x <= 1; ++x)
        for (int y = -1; y <= 1; ++y)
          for (int z = -1; z <= 1; ++z) all[i++] = {x, y, z};
      return all;
    }();
    if (neighbours >= 27) return kAll;
    if (neighbours >= 7) return kSeven;
    return kOne;
  }
  void merge_pending(const VoxelKey& index, GaussianVoxel& voxel);
  void update_cache(GaussianVoxel& voxel) const;

  GaussianVoxelMapOptions options_;
  double inverse_size_ = 1.0;
  bool exact_inverse_ = false;  ///< 1 / voxel size is exact (a power of two)
  std::uint64_t insert_calls_ = 0;
  VoxelHashTable<GaussianVoxel> voxels_;
};

}  // namespace scanmatch
