#pragma once
// The fine stage of CTF-ICP: frame-to-map. Each point of the preprocessed frame is paired with the
// map voxel it falls in; the voxel's covariance keeps its eigenvectors and gets eigenvalues
// (1, 1, eps), so the cost is the point's distance to the voxel's plane. Plain Gauss-Newton that
// re-pairs every step, with a Cauchy kernel on the plane distance and the degeneracy guard
// (directions the map does not constrain keep the start's value).

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/geometry/gaussian_voxel_map.hpp"
#include "scanmatch/odometry/odometry_config.hpp"
#include "scanmatch/registration/factors/ctf_fine.hpp"

namespace scanmatch {

struct FineResult {
  Pose pose = Pose::Identity();  ///< in the map frame (the start when not registered)
  bool registered = false;       ///< enough points were paired; false: pose is the start
  int iterations = 0;
  std::size_t paired = 0;  ///< points paired with a map voxel in the last linearisation
  double condition_number = 0.0;
  int degenerate_directions = 0;  ///< directions left at the start (when registered)
};

class FineStage {
 public:
  explicit FineStage(const OdometryConfig& config);
  /// Registers `frame` (preprocessed, sensor frame) to `map` from the pose `start`.
  /// No update along the directions degenerate by config.degeneracy_guard_ratio, or by
  /// config.degeneracy_ratio while the map is young (`young_map`).
  FineResult refine(const PointCloud& frame, const GaussianVoxelMap& map, const Pose& start,
                    bool young_map) const;

 private:
  CtfFineOptions options_;
  double reported_degeneracy_ratio_ = 0.0, guard_ratio_ = 0.0;
};

}  // namespace scanmatch
