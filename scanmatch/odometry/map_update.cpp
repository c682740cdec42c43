#include "scanmatch/odometry/map_update.hpp"

#include "scanmatch/geometry/voxel_filter.hpp"

namespace scanmatch {
namespace {

GaussianVoxelMapOptions map_options(const OdometryConfig& c) {
  GaussianVoxelMapOptions o;
  o.voxel_size = c.map_voxel_size;
  o.merge_threshold = c.merge_threshold;
  o.planar_epsilon = c.registration.ctf_epsilon;
  o.max_points = c.map_voxel_max_points;
  o.min_points = c.map_voxel_min_points;
  o.distributions = false;  // the fine stage reads means and normals only
  return o;
}

}  // namespace

MapUpdate::MapUpdate(const OdometryConfig& config)
    : fine_stage_(config.fine_stage),
      map_update_(config.map_update),
      radius_(config.map_radius),
      map_(map_options(config)) {}

void MapUpdate::add(const PointCloud& frame, const Pose& pose, bool first) {
  if (!fine_stage_) return;  // nothing reads the map
  if (!map_update_) {
    // Ablation: the fine stage sees only the previous frame.
    if (frame.empty()) return;
    map_.clear();
    map_.insert(frame, pose);
    map_.flush();
    return;
  }
  // Points beyond the radius would be pruned anyway: keep them out so the bound is strict.
  bool beyond = false;
  const double r2 = radius_ * radius_;
  for (const Point& p : frame.points) beyond = beyond || p.squaredNorm() > r2;
  map_.insert(beyond ? crop_range(frame, 0.0, radius_) : frame, pose);
  if (first) map_.flush();
  // Pruning scans the whole map: do it once the sensor has moved a tenth of the radius.
  if ((pose.translation() - last_prune_).norm() > 0.1 * radius_) {
    map_.remove_far(pose.translation(), radius_);
    last_prune_ = pose.translation();
  }
}

}  // namespace scanmatch
