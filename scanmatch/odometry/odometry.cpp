#include "scanmatch/odometry/odometry.hpp"

#include "scanmatch/odometry/ctf_icp_odometry.hpp"
#include "scanmatch/odometry/frame_to_frame_odometry.hpp"

namespace scanmatch {

std::unique_ptr<OdometryPipeline> make_odometry_pipeline(const OdometryConfig& config) {
  // The pipelines check the rest of the configuration.
  if (config.method == "ctf-icp") return std::make_unique<CtfIcpOdometry>(config);
  return std::make_unique<FrameToFrameOdometry>(config);
}

Odometry::Odometry(const OdometryConfig& config) : pipeline_(make_odometry_pipeline(config)) {}
Odometry::~Odometry() = default;
Odometry::Odometry(Odometry&&) noexcept = default;
Odometry& Odometry::operator=(Odometry&&) noexcept = default;

Pose Odometry::register_frame(const PointCloud& frame, double timestamp) {
  return pipeline_->register_frame(frame, timestamp);
}

const FrameStats& Odometry::last_stats() const {
  return pipeline_->last_stats();
}

const OdometryConfig& Odometry::config() const {
  return pipeline_->config();
}

std::size_t Odometry::frames() const {
  return pipeline_->frames();
}

}  // namespace scanmatch
