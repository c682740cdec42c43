#pragma once
// LiDAR odometry: one pipeline configured by method.
//
// `ctf-icp` is docs/methods.md section 1: deskew and voxel-downsample the frame; coarse stage NDT
// frame-to-frame (against the previous frame's NDT grid, from the constant-velocity prior); fine
// stage frame-to-map on the global Gaussian map with covariance eigenvalues normalised to
// (1, 1, 1e-6); map update that merges a voxel once 5 new points are pending (merge rule of the
// paper with the outer-product term); the map keeps only voxels within `map_radius` of the sensor.
// Every other method is a registration method (registration/methods.hpp) run frame-to-frame from
// the same prior, as in the papers' comparisons.
//
// Degeneracy: the fine stage's information matrix is analysed each frame (solver.hpp,
// analyse_degeneracy); along directions it does not constrain (a plain corridor's axis) the
// solver makes no update and the pose keeps the fine stage's start there (the coarse NDT result,
// itself started from the constant-velocity prior).

#include <cstddef>
#include <string>

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/geometry/gaussian_voxel_map.hpp"
#include "scanmatch/odometry/adaptive_state.hpp"
#include "scanmatch/odometry/frame_stats.hpp"
#include "scanmatch/registration/methods.hpp"

namespace scanmatch {

struct OdometryConfig {
  std::string method = "ctf-icp";  ///< ctf-icp or any registration method (frame-to-frame)
  double voxel_size = 0.25;        ///< m, downsampling of every frame (0: none)
  double min_range = 0.3;          ///< m: nearer points (the robot itself) are dropped
  double max_range = 100.0;        ///< m: farther points are dropped
  // Coarse stage (ctf-icp): NDT against the previous frame.
  double ndt_resolution = 1.0;     ///< m, the NDT grid of the previous frame
  int ndt_neighbours = 1;          ///< voxels per point: 1, 7 or 27
  double coarse_voxel_size = 0.7;  ///< m, further downsampling of the NDT source (0: none)
  int coarse_max_iterations = 30;
  double coarse_tolerance = 1e-4;  ///< m and rad: the coarse stage stops below this update
  // Fine stage (ctf-icp): frame-to-map.
  double map_voxel_size = 0.5;        ///< m, the global Gaussian map
  std::uint32_t merge_threshold = 5;  ///< points pending before a map voxel is merged
  double map_radius = 50.0;  ///< m: map voxels farther from the sensor are dropped (checked
                             ///< whenever the sensor has moved a tenth of it)
  /// Points a map voxel needs before the fine stage uses it.
  std::uint32_t map_voxel_min_points = 5;
  /// Points after which a map voxel is frozen (GaussianVoxelMapOptions::max_points; 0: never).
  std::uint32_t map_voxel_max_points = 0;
  int fine_max_iterations = 10;
  double fine_tolerance = 1e-4;  ///< m and rad: the fine stage stops below this update
  /// Map voxels flatter than this (smallest / middle eigenvalue) are used; 1: all (the paper).
  double fine_max_flatness = 1.0;
  /// m: plane distance where the fine stage's Cauchy kernel starts to down-weight (0: no kernel)
  double fine_kernel_distance = 0.1;
  /// Degeneracy guard of the fine stage (SolverOptions::degeneracy_ratio; 0: off).
  double degeneracy_ratio = 0.02;
  // Ablations of the paper's Table 5.
  bool fine_stage = true;  ///< false: coarse NDT only
  /// false: no global map; the fine stage registers against a map of the previous frame only.
  bool map_update = true;
  /// Constant-velocity motion prior; false: the previous pose is the initial guess.
  bool constant_velocity = true;
  /// Move each point to the frame's middle with the constant-velocity motion (needs point times);
  /// the reported poses are still frame-start poses.
  bool deskew = true;
  /// Frames whose motion prior is below both thresholds are not deskewed: their distortion is
  /// below the sensor noise, and deskewing by a velocity that is itself estimation noise feeds that
  /// noise back into the next pose (a still sensor then drifts).
  double deskew_min_translation = 0.01;  ///< m per frame
  double deskew_min_rotation = 0.002;    ///< rad per frame
  double max_jump = 1.0;        ///< m: a result farther than this from the prior is rejected
  double max_jump_angle = 1.0;  ///< rad: likewise for rotation (hand-held motion turns fast)
  // Sparse and irregular frames (odometry/adaptive.hpp; docs/odometry.md "Sparse keyframes").
  /// Scale the constant-velocity prior by the ratio of the frame time steps.
  bool time_scaled_prior = true;
  double max_step_ratio = 4.0;  ///< time-step ratios beyond this (or its inverse) are uncertain
  /// A frame whose estimate lies farther than this from its prior makes the next prior uncertain.
  double prior_miss_distance = 0.2;  ///< m
  double prior_miss_angle = 0.05;    ///< rad
  /// ctf-icp, uncertain prior: try other coarse starts (identity, half and twice the prior).
  bool uncertain_starts = true;
  double uncertain_ndt_scale = 3.0;   ///< the other starts run first on this times ndt_resolution
  double uncertain_jump_scale = 3.0;  ///< max_jump and max_jump_angle widen by this factor
  /// Sparse frames (fewer than 10 times this many points) keeping fewer points after the voxel
  /// filter are downsampled with smaller voxels (down to voxel_size / 4; 0: off).
  std::uint32_t min_downsampled_points = 1000;
  int threads = 1;
  RegistrationOptions registration;  ///< parameters of the frame-to-frame baselines
};

/// "ctf-icp, icp, ...": the odometry's methods (ctf-icp and every registration method).
std::string odometry_method_list();
/// ctf-icp or a registration method (optional peers: frame_odometry.hpp).
bool is_odometry_method(const std::string& name);

class Odometry {
 public:
  /// Throws Error for an unknown method or invalid parameters.
  explicit Odometry(const OdometryConfig& config);
  /// Registers the next frame (points in the sensor frame; per-point `time` offsets from the frame
  /// start enable deskewing) taken at `timestamp` seconds; returns the sensor pose at the frame
  /// start in the world frame of the first frame. Never throws for bad frames: an empty or
  /// unregistrable frame is bridged by the motion prior (last_stats().bridged).
  Pose register_frame(const PointCloud& frame, double timestamp);
  /// The global Gaussian map (ctf-icp), in the internal world frame: world_from_map() * x gives
  /// the world frame of the returned poses (they differ by half of frame 0's motion when frames
  /// carry point times, since the internal origin is frame 0's mid-frame pose).
  const GaussianVoxelMap& map() const { return map_; }
  const Pose& world_from_map() const { return world_from_internal_; }
  /// The last registered frame, downsampled and deskewed, in its sensor frame at mid-frame (the
  /// frame start when frames carry no point times); last_internal_pose() places it in map().
  const PointCloud& last_frame() const { return previous_; }
  const Pose& last_internal_pose() const { return pose_; }
  const FrameStats& last_stats() const { return stats_; }
  const OdometryConfig& config() const { return config_; }
  std::size_t frames() const { return frames_; }

 private:
  PointCloud preprocess(const PointCloud& frame) const;
  /// Motion above `factor` times the deskew dead band.
  bool moving(const Pose& motion, double factor = 1.0) const;
  Pose register_ctf(const PointCloud& down, const PointCloud& coarse, const Pose& predicted);
  Pose register_baseline(const PointCloud& down, const Pose& predicted);

  OdometryConfig config_;
  GaussianVoxelMap map_;
  GaussianVoxelMap previous_ndt_;  ///< the previous frame's NDT grid, in its sensor frame
  PointCloud previous_;
  /// pose_: mid-frame pose of the last frame (frame start when frames carry no point times);
  /// velocity_: motion between the last two such poses.
  Pose pose_ = Pose::Identity(), velocity_ = Pose::Identity();
  Pose world_from_internal_ = Pose::Identity();
  double last_timestamp_ = 0.0, frame_period_ = 0.1;
  double ndt_d1_ = 0.0, ndt_d2_ = 0.0;
  Eigen::Vector3d last_prune_ = Eigen::Vector3d::Zero();  ///< where the map was last pruned
  std::size_t frames_ = 0;
  bool timed_frames_ = false;  ///< the first frame had point times: poses are mid-frame internally
  AdaptiveState adaptive_;     ///< sparse and irregular frames (adaptive.hpp)
  FrameStats stats_;
};

}  // namespace scanmatch
