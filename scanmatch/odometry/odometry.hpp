#pragma once
// LiDAR odometry, ours: `ctf-icp` (CtfIcpOdometry: NDT coarse stage frame-to-frame, fine stage
// frame-to-map on the global Gaussian map, map update; docs/methods.md section 1) or any
// registration method frame-to-frame (FrameToFrameOdometry), as in the papers' comparisons.
//
// Where each part lives (odometry/):
//   odometry_config.hpp        every parameter (described once in config/odometry_fields.hpp)
//   odometry_pipeline.hpp      the frame loop both pipelines share
//   preprocessor.hpp           range crop, deskew, adaptive voxel filter
//   motion_model.hpp           the motion prior, its uncertainty, the gate
//   coarse_ndt.hpp             CTF-ICP's coarse stage
//   fine_stage.hpp             CTF-ICP's fine stage
//   map_update.hpp             CTF-ICP's global map
//   ctf_icp_odometry.hpp       CTF-ICP: the stages chained
//   frame_to_frame_odometry.hpp  any registration method, frame to frame
//   frame_odometry.hpp         the interface the runner and `bench` drive, and optional peers

#include <cstddef>
#include <memory>

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/odometry/frame_odometry.hpp"
#include "scanmatch/odometry/frame_stats.hpp"
#include "scanmatch/odometry/odometry_config.hpp"

namespace scanmatch {

class OdometryPipeline;

/// Ours for config.method: CtfIcpOdometry for ctf-icp, FrameToFrameOdometry for a registration
/// method. Throws Error for an unknown method or invalid parameters.
std::unique_ptr<OdometryPipeline> make_odometry_pipeline(const OdometryConfig& config);

/// Our odometry for config.method, frame by frame.
class Odometry {
 public:
  /// Throws Error for an unknown method or invalid parameters.
  explicit Odometry(const OdometryConfig& config);
  ~Odometry();
  Odometry(Odometry&&) noexcept;
  Odometry& operator=(Odometry&&) noexcept;
  /// Registers the next frame (points in the sensor frame; per-point `time` offsets from the frame
  /// start enable deskewing) taken at `timestamp` seconds; returns the sensor pose at the frame
  /// start in the world frame of the first frame. Never throws for bad frames: an empty or
  /// unregistrable frame is bridged by the motion prior (last_stats().bridged).
  Pose register_frame(const PointCloud& frame, double timestamp);
  const FrameStats& last_stats() const;
  const OdometryConfig& config() const;
  std::size_t frames() const;
  /// The pipeline itself (for its last frame, internal pose and, for ctf-icp, its map).
  const OdometryPipeline& pipeline() const { return *pipeline_; }

 private:
  std::unique_ptr<OdometryPipeline> pipeline_;
};

}  // namespace scanmatch
