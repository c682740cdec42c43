#pragma once
// LiDAR odometry: one pipeline configured by method. `ctf-icp` is METHODS.md section 1 (voxel
// downsampling, NDT frame-to-frame coarse stage from a constant-velocity prior, frame-to-map fine
// stage on the global Gaussian map with eigenvalues normalised to (1, 1, 1e-6), map update that
// merges a voxel once 5 new points are pending, map bounded by a radius). Every other registration
// method runs frame-to-frame from the same prior, as in the papers' comparisons.
// (First version: no degeneracy guard yet; deskewing uses the previous frame's motion.)

#include <string>

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/geometry/gaussian_voxel_map.hpp"
#include "scanmatch/registration/methods.hpp"

namespace scanmatch {

struct OdometryConfig {
  std::string method = "ctf-icp";     ///< ctf-icp or any registration method (frame-to-frame)
  double voxel_size = 0.25;           ///< m, downsampling of every frame
  double ndt_resolution = 1.0;        ///< m, the coarse NDT grid
  double map_voxel_size = 0.5;        ///< m, the global Gaussian map
  std::uint32_t merge_threshold = 5;  ///< points pending before a map voxel is merged
  double map_radius = 80.0;           ///< m, map voxels farther from the sensor are dropped
  bool fine_stage = true;             ///< ablation: false = coarse only
  bool map_update = true;             ///< ablation: false = the map of the first frame only
  /// Move each point to the frame start with the previous frame's motion (needs point times).
  bool deskew = true;
  double max_jump = 1.0;         ///< m: a result farther than this from the prior is rejected
  double max_jump_angle = 0.35;  ///< rad: likewise for rotation
  int threads = 1;
  RegistrationOptions registration;  ///< solver and method parameters
};

struct FrameStats {
  double preprocess_ms = 0, coarse_ms = 0, fine_ms = 0, map_ms = 0, total_ms = 0;
  std::size_t points_in = 0, points_downsampled = 0;
  int iterations = 0;
  double condition_number = 0;
  bool bridged = false;  ///< the frame could not be registered: the motion prior was used
};

class Odometry {
 public:
  explicit Odometry(const OdometryConfig& config);
  /// Registers the next frame; returns its pose in the world frame of the first frame.
  Pose register_frame(const PointCloud& frame, double timestamp);
  const GaussianVoxelMap& map() const { return map_; }
  const FrameStats& last_stats() const { return stats_; }
  const OdometryConfig& config() const { return config_; }

 private:
  OdometryConfig config_;
  GaussianVoxelMap map_;
  PointCloud previous_;
  Pose pose_ = Pose::Identity(), velocity_ = Pose::Identity();  ///< velocity_: last frame's motion
  double last_timestamp_ = 0.0, frame_period_ = 0.1;
  std::size_t frames_ = 0;
  FrameStats stats_;
};

}  // namespace scanmatch
