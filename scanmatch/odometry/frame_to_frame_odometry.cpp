#include "scanmatch/odometry/frame_to_frame_odometry.hpp"

#include "scanmatch/core/stopwatch.hpp"
#include "scanmatch/registration/methods.hpp"

namespace scanmatch {
namespace {

RegistrationOptions registration_options(const OdometryConfig& config) {
  RegistrationOptions o = config.registration;
  o.method = config.method;
  return o;
}

}  // namespace

FrameToFrameOdometry::FrameToFrameOdometry(const OdometryConfig& config)
    : OdometryPipeline(config, /*keep_attributes=*/true, /*map_points=*/false,
                       /*deskews_again=*/false),
      registration_(registration_options(this->config())),
      minimum_points_(minimum_points(config.method, config.registration)) {}

Pose FrameToFrameOdometry::estimate(const PointCloud& frame, const MotionPrior& prior,
                                    const Pose& predicted, FrameStats& stats) {
  if (frame.size() < minimum_points_ || previous_.size() < minimum_points_) {
    stats.bridged = true;
    return predicted;
  }
  const Stopwatch time;
  const RegistrationResult r = register_clouds(frame, previous_, registration_, prior.motion);
  stats.coarse_ms = time.ms();
  stats.iterations = r.iterations;
  stats.condition_number = r.condition_number;
  return last_internal_pose() * r.transform;
}

void FrameToFrameOdometry::update_reference(PointCloud frame, const PointCloud&, const Pose&,
                                            bool bridged, FrameStats&) {
  if (!frame.empty() || !bridged) previous_ = std::move(frame);
}

}  // namespace scanmatch
