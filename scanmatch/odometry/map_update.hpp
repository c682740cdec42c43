#pragma once
// The map of CTF-ICP and its update: a global Gaussian voxel map (map_voxel_size) around the
// sensor. Each registered frame's points within map_radius are added at its pose; a voxel merges
// its pending points once merge_threshold are pending (the paper's merge rule with the outer
// product term). Voxels farther than map_radius are dropped whenever the sensor has moved a tenth
// of it, so memory stays bounded on long runs. The first frame builds the map at once.
//
// Ablations: without the fine stage nothing reads the map and it is not built; with map_update
// off it holds only the last frame.

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/geometry/gaussian_voxel_map.hpp"
#include "scanmatch/odometry/odometry_config.hpp"

namespace scanmatch {

class MapUpdate {
 public:
  explicit MapUpdate(const OdometryConfig& config);
  /// Adds `frame` (preprocessed, sensor frame) at `pose`; `first` builds the map at once.
  void add(const PointCloud& frame, const Pose& pose, bool first);
  const GaussianVoxelMap& map() const { return map_; }

 private:
  bool fine_stage_, map_update_;
  double radius_;
  GaussianVoxelMap map_;
  Eigen::Vector3d last_prune_ = Eigen::Vector3d::Zero();  ///< where the map was last pruned
};

}  // namespace scanmatch
