#include "scanmatch/odometry/ctf_icp_odometry.hpp"

#include "scanmatch/core/stopwatch.hpp"

namespace scanmatch {

CtfIcpOdometry::CtfIcpOdometry(const OdometryConfig& config)
    : OdometryPipeline(config, /*keep_attributes=*/false, config.dense_sparse_map,
                       /*deskews_again=*/true),
      coarse_(config),
      fine_(config),
      map_(config),
      fine_stage_(config.fine_stage) {}

Pose CtfIcpOdometry::estimate(const PointCloud& frame, const MotionPrior& prior,
                              const Pose& predicted, FrameStats& stats) {
  if (frame.size() < kMinimumFramePoints) {
    stats.bridged = true;
    return predicted;
  }
  const Stopwatch coarse_time;
  const CoarseResult coarse = coarse_.align(frame, prior);
  Pose estimate = last_internal_pose() * coarse.motion;
  stats.iterations = coarse.iterations;
  stats.condition_number = coarse.condition_number;
  stats.recovered = coarse.recovered;
  stats.coarse_ms = coarse_time.ms();

  if (fine_stage_ && map_.map().size() > 0) {
    const Stopwatch fine_time;
    const bool young_map = frames() < static_cast<std::size_t>(config().degeneracy_guard_frames);
    const FineResult fine = fine_.refine(frame, map_.map(), estimate, young_map);
    const Pose disagreement = estimate.inverse() * fine.pose;
    stats.coarse_fine_m = disagreement.translation().norm();
    stats.coarse_fine_deg = rotation_angle(disagreement) * kDegreesPerRadian;
    stats.fine_paired_fraction =
        static_cast<double>(fine.paired) / static_cast<double>(frame.size());
    estimate = fine.pose;
    stats.degenerate_directions = fine.degenerate_directions;
    stats.iterations += fine.iterations;
    stats.condition_number = fine.condition_number;
    stats.fine_ms = fine_time.ms();
  }
  return estimate;
}

void CtfIcpOdometry::update_reference(PointCloud frame, const PointCloud& map_points,
                                      const Pose& pose, bool bridged, FrameStats& stats) {
  const Stopwatch map_time;
  map_.add(map_points.empty() ? frame : map_points, pose, frames() == 0);
  coarse_.set_reference(std::move(frame), bridged);
  stats.map_ms = map_time.ms();
}

void CtfIcpOdometry::restart_reference(PointCloud first, const PointCloud& map_points) {
  map_ = MapUpdate(config());
  map_.add(map_points.empty() ? first : map_points, Pose::Identity(), /*first=*/true);
  coarse_ = CoarseNdt(config());
  coarse_.set_reference(std::move(first), /*bridged=*/false);
}

}  // namespace scanmatch
