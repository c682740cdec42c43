#include "scanmatch/odometry/ctf_icp_odometry.hpp"

#include "scanmatch/core/error.hpp"
#include "scanmatch/core/stopwatch.hpp"
#include "scanmatch/odometry/health.hpp"
#include "scanmatch/registration/global_registration.hpp"
#include "scanmatch/registration/methods.hpp"

namespace scanmatch {

CtfIcpOdometry::CtfIcpOdometry(const OdometryConfig& config)
    : OdometryPipeline(config, /*keep_attributes=*/false, config.dense_sparse_map,
                       /*deskews_again=*/true),
      coarse_(this->config()),
      fine_(this->config()),
      map_(this->config()),
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
  // A winner outside the motion gate would be thrown away and the frame bridged by the bare prior.
  // An overlay near the identity often wins the score on big steps (a car 14 m on, a hand turned
  // 30 deg: more of the frame falls inside the last one's view there), while the prior's own
  // solve, inside the gate, was right: the first optimum inside the gate serves instead.
  bool recovered = coarse.recovered;
  if (!within_gate(predicted, estimate))
    for (std::size_t k = 0; k < coarse.alternatives.size(); ++k)
      if (within_gate(predicted, last_internal_pose() * coarse.alternatives[k])) {
        estimate = last_internal_pose() * coarse.alternatives[k];
        recovered = !(coarse.recovered && k == 0);  // the first is the plain result's
        break;
      }
  stats.iterations = coarse.iterations;
  stats.condition_number = coarse.condition_number;
  stats.recovered = recovered;
  stats.coarse_ms = coarse_time.ms();

  // While the map holds frame 0 alone, it is the coarse stage's own reference seen through
  // biased voxels: a 0.5 m voxel gets at most 4 of an axis-aligned wall's 0.25 m-downsampled
  // points, so the ones that reach map_voxel_min_points are corners and oblique surfaces (a still
  // MID-360's frame 1: 12 % paired, 6 mm and 0.27 deg off). Frame 1 is refined against frame 0 at
  // map density instead.
  const GaussianVoxelMap& target =
      frames() == 1 && first_frame_map_ ? first_frame_map_->map() : map_.map();
  if (fine_stage_ && target.size() > 0) {
    const Stopwatch fine_time;
    const bool young_map = frames() < static_cast<std::size_t>(config().degeneracy_guard_frames);
    const FineResult fine = fine_.refine(frame, target, estimate, young_map);
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
    // Only the first motion, whose prior is no information at all: later priors carry a measured
    // motion, and a long true step overlaps the last frame less than an overlay near standing
    // still does (docs/odometry.md, "Global start"). Where the map held the frame well it
    // overlaps the last frame too (the thin-map health rule first: the overlap costs a k-d tree).
    if (frames() == 1 && config().global_start_below > 0.0 &&
        stats.fine_paired_fraction < health::kThinPairedFraction)
      estimate = global_start(frame, target, young_map, estimate, stats);
  }
  return estimate;
}

double CtfIcpOdometry::overlap_with_last(const PointCloud& frame, const Pose& pose) const {
  std::size_t matched = 0;
  fitness_score(frame, coarse_.reference(), last_internal_pose().inverse() * pose,
                GlobalRegistrationOptions{}.feature_voxel_size, &matched);
  return static_cast<double>(matched) / static_cast<double>(frame.size());
}

Pose CtfIcpOdometry::global_start(const PointCloud& frame, const GaussianVoxelMap& target,
                                  bool young_map, const Pose& estimate, FrameStats& stats) {
  const Stopwatch time;
  // Judged against the last frame, as the global stage sees it: the fine stage's paired share
  // depends on how dense the map is where a pose puts the frame (a straight street's walls and
  // road pair a quarter of a frame left standing 10 m behind).
  const double local = overlap_with_last(frame, estimate);
  if (local >= config().global_start_below) {
    stats.coarse_ms += time.ms();
    return estimate;
  }
  GlobalRegistrationOptions options;
  options.num_threads = config().threads;
  GlobalRegistrationResult global;
  try {
    global = register_global(frame, coarse_.reference(), options);
  } catch (const Error&) {
    global.success = false;  // too few points for features: the frame keeps its local result
  }
  stats.coarse_ms += time.ms();
  if (!global.success) return estimate;
  const Stopwatch fine_time;
  const FineResult fine =
      fine_.refine(frame, target, last_internal_pose() * global.transform, young_map);
  stats.fine_ms += fine_time.ms();
  if (overlap_with_last(frame, fine.pose) < config().global_start_gain * local) return estimate;
  stats.global_start = true;
  stats.fine_paired_fraction = static_cast<double>(fine.paired) / static_cast<double>(frame.size());
  stats.degenerate_directions = fine.degenerate_directions;
  stats.iterations += fine.iterations;
  stats.condition_number = fine.condition_number;
  return fine.pose;
}

void CtfIcpOdometry::update_reference(PointCloud frame, const PointCloud& map_points,
                                      const Pose& pose, bool bridged, FrameStats& stats) {
  const Stopwatch map_time;
  wait_for_reference();
  if (frames() >= 1) first_frame_map_.reset();
  // Frames 0 and 1 build the map at once: frame 2 registers against both.
  const bool first = frames() <= 1;
  if (config().threads > 1 && !first) {
    // The map points are the pipeline's, reused by the next frame: the task keeps its own.
    PointCloud points = map_points.empty() ? PointCloud{} : map_points;
    reference_update_.work = std::async(
        std::launch::async,
        [this, frame = std::move(frame), points = std::move(points), pose, bridged]() mutable {
          map_.add(points.empty() ? frame : points, pose, false);
          coarse_.set_reference(std::move(frame), bridged);
        });
  } else {
    map_.add(map_points.empty() ? frame : map_points, pose, first);
    coarse_.set_reference(std::move(frame), bridged);
  }
  stats.map_ms += map_time.ms();
}

void CtfIcpOdometry::wait_for_reference() const {
  if (reference_update_.work.valid()) reference_update_.work.get();
}

void CtfIcpOdometry::set_first_frame_detail(PointCloud detail) {
  if (!fine_stage_ || !config().map_update || detail.empty()) return;
  first_frame_map_.emplace(config());
  first_frame_map_->add(detail, Pose::Identity(), /*first=*/true);
}

void CtfIcpOdometry::restart_reference(PointCloud first, const PointCloud& map_points) {
  wait_for_reference();
  map_ = MapUpdate(config());
  map_.add(map_points.empty() ? first : map_points, Pose::Identity(), /*first=*/true);
  coarse_ = CoarseNdt(config());
  coarse_.set_reference(std::move(first), /*bridged=*/false);
}

}  // namespace scanmatch
