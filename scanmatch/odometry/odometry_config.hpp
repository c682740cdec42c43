#pragma once
// The configuration of the 3D odometry (every pipeline and stage reads its part of it). Each field
// is described once, with its JSON key and flag, in config/odometry_fields.hpp.

#include <cmath>
#include <cstdint>
#include <string>

#include "scanmatch/registration/options.hpp"

namespace scanmatch {

struct OdometryConfig {
  std::string method = "ctf-icp";  ///< ctf-icp or any registration method (frame-to-frame)
  double voxel_size = 0.25;        ///< m, downsampling of every frame (0: none)
  double min_range = 0.3;          ///< m: nearer points (the robot itself) are dropped
  double max_range = 100.0;        ///< m: farther points are dropped
  /// deg: every point's elevation is lowered by this before anything else, for a sensor whose
  /// beams point lower than its points say (geometry/beam_elevation.hpp; docs/odometry.md,
  /// "riverside02_keyframes: what is left"). 0: as delivered.
  double elevation_correction_deg = 0.0;
  /// Without an elevation_correction_deg: estimate the bias from the first moving frame pairs and
  /// take it out of the frames after them where the pairs agree on one
  /// (odometry/elevation_estimate.hpp).
  bool elevation_estimate = true;
  // Coarse stage (ctf-icp): NDT against the previous frame.
  double ndt_resolution = 1.0;     ///< m, the NDT grid of the previous frame
  int ndt_neighbours = 1;          ///< voxels per point: 1, 7 or 27
  double coarse_voxel_size = 0.7;  ///< m, further downsampling of the NDT source (0: none)
  /// A denser NDT source is thinned further, to about this many points (0: no limit). The stage
  /// only has to reach the fine stage's basin, and its cost grows with the points: a 64-beam car
  /// scan keeps 11k at 0.7 m, a Livox frame 1-2k (docs/benchmarks.md, "Dense scans").
  std::uint32_t max_coarse_points = 4000;
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
  /// Directions of the fine stage's information below this share of the largest (rotations as
  /// displacements at the frame's RMS range) are reported degenerate (timing.csv; 0: none).
  double degeneracy_ratio = 0.02;
  /// The fine stage makes no update along directions below this ratio (Zhang et al.'s solution
  /// remapping), keeping the coarse result there: only views that hold nothing along them (one
  /// wall in a 70-deg field of view). A plain corridor's axis (0.005-0.02) is held better by the
  /// map than by frame-to-frame NDT, whose result slides (docs/odometry.md, Degeneracy).
  double degeneracy_guard_ratio = 0.005;
  /// Over the first this-many frames the guard uses degeneracy_ratio: a map of a frame or two
  /// cannot hold what a wider view would (a start inside a turn tilted 1.5 deg without it).
  int degeneracy_guard_frames = 10;
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
  /// ctf-icp (whose registration is trusted more than the prior): a frame was deskewed by its
  /// prior; where the registered motion differs from that prior by
  /// more than these, the frame is deskewed again by the registered motion and registered again
  /// from its pose (a hand-held sensor's turn rate changes within a frame or two, and the prior's
  /// distortion is then left in the map). The first two frames, which no measured velocity can
  /// deskew, are deskewed once the first motion is measured and the reference restarted from
  /// them. Both 0: never (and the first frames stay as they are).
  double redeskew_translation = 0.05;  ///< m per frame
  double redeskew_rotation = 0.0175;   ///< rad per frame (1 deg)
  /// Frames that carry no point times get them from each point's azimuth (spin_times.hpp) before
  /// preprocessing, as a spinning sensor measured them, so they are deskewed too; frames with
  /// times keep theirs. Off by default: a cloud does not say whether its sweep is raw or already
  /// deskewed (KITTI's odometry benchmark scans were motion-compensated by the data set, its raw
  /// scans were not; both are .bin files without times).
  bool spin_times = false;
  double spin_period = 0.1;  ///< s per turn of the sensor
  /// rad: where each sweep starts (atan2(y, x), 0 along +x): behind the sensor, as KITTI's scans.
  double spin_start_azimuth = M_PI;
  bool spin_clockwise = true;  ///< seen from above (Velodyne sensors turn clockwise)
  /// The world is frame 0's start, half of frame 0's motion before the internal origin (its
  /// middle), known only from the first measured motions. Each part of that motion anchors the
  /// world only above these: a wrong rotation turns every later pose about the start (a ground
  /// robot's 0.3 deg of jitter per frame on dynamic-indoor: 20 mm over 7.5 m), a wrong translation
  /// only offsets them.
  double anchor_min_translation = 0.01;  ///< m per frame
  double anchor_min_rotation = 0.0175;   ///< rad per frame (1 deg)
  double max_jump = 1.0;        ///< m: a result farther than this from the prior is rejected
  double max_jump_angle = 1.0;  ///< rad: likewise for rotation (hand-held motion turns fast)
  // Sparse and irregular frames (motion_model.hpp, preprocessor.hpp; docs/odometry.md "Sparse
  // keyframes").
  /// Scale the constant-velocity prior by the ratio of the frame time steps.
  bool time_scaled_prior = true;
  double max_step_ratio = 4.0;  ///< time-step ratios beyond this (or its inverse) are uncertain
  /// A frame whose estimate lies farther than this from its prior makes the next prior uncertain.
  double prior_miss_distance = 0.2;  ///< m
  double prior_miss_angle = 0.05;    ///< rad
  /// A prior that turns more than this in one step is uncertain: a constant-velocity guess of a
  /// sensor that turns by hand (or keyframes taken every few degrees) misses by about as much as it
  /// turns, while a vehicle at 10 Hz turns a degree or two a frame (docs/odometry.md, "Recorded
  /// Avia keyframes").
  double uncertain_rotation = 0.05;  ///< rad
  /// ctf-icp, uncertain prior: try other coarse starts (identity, half and twice the prior, and
  /// the prior turned about the sensor's z axis by +-k * rotation_start_step, k
  /// = 1..rotation_starts).
  bool uncertain_starts = true;
  int rotation_starts = 2;              ///< turned starts per side (0: none)
  double rotation_start_step = 0.0873;  ///< rad (5 deg)
  double uncertain_ndt_scale = 3.0;     ///< the other starts run first on this times ndt_resolution
  /// m: that first descent takes the coarse points downsampled further to this (at most
  /// coarse_voxel_size: none). Most of a start's iterations are spent there, and it only has to
  /// reach the normal grid's basin (avia_hku1: coarse stage 2.2x faster, ATE 0.0485 -> 0.0509 m;
  /// docs/benchmarks.md, "Speed on recorded frames").
  double start_voxel_size = 1.0;
  /// ctf-icp: a certain prior whose NDT solve took at least this many iterations is also
  /// registered first on the wider grid (uncertain_ndt_scale), then on the normal one, and that
  /// result kept when it scores better (0: never). The normal grid's basin along a surface is
  /// about a cell: on ground seen from low down the score ripples with the cells, and a prior
  /// 0.5 m or a few degrees off (a car entering a turn) stops in a ripple, slowly.
  int wide_start_iterations = 15;
  /// ctf-icp, uncertain prior: the other starts are first solved and ranked on every n-th coarse
  /// point, about this many, and only the best start_full_solves that beat the plain result there
  /// are solved on every point (0: every start solved on every point). Off by default: 150 makes
  /// the coarse stage 2-5x cheaper on avia_hku1 and riverside02_keyframes at the same or better
  /// ATE, but sim:handheld-fast's ATE is 30 % worse over six seeds (docs/benchmarks.md, "Speed on
  /// recorded frames").
  std::uint32_t start_screen_points = 0;
  /// ... and only this many best-ranked starts are then solved on every point.
  int start_full_solves = 1;
  double uncertain_jump_scale = 3.0;  ///< max_jump and max_jump_angle widen by this factor
  /// ctf-icp, the first motion (no prior at all), a thin map (health.hpp): where less than this
  /// share of the frame's points lies within 0.5 m (the global stage's feature voxel) of the first
  /// frame's, the frame is also registered onto it with no prior
  /// (registration/global_registration.hpp: FPFH features and a maximum consistent set) and refined
  /// against the map from there; that result replaces the first, beyond the motion gate if need be,
  /// where global_start_gain times as many points overlap. A keyframe folder may start metres from
  /// where the identity guess puts it; consecutive frames overlap 0.8-0.9 (0: off). Not for later
  /// frames: a long true step overlaps the last frame less than an overlay near standing still
  /// (docs/odometry.md).
  double global_start_below = 0.5;
  double global_start_gain = 1.3;
  /// Sparse frames (fewer than 10 times this many points) keeping fewer points after the voxel
  /// filter are downsampled with smaller voxels (down to voxel_size / 4; 0: off).
  std::uint32_t min_downsampled_points = 1000;
  /// Frames keeping more points after the voxel filter are filtered at a larger voxel that keeps
  /// under this many (0: no limit), learned from the last such frame so that each is filtered once.
  /// A 64-beam car scan keeps ~40k at 0.25 m and every later stage touches each of them; at 15000
  /// (~12k kept, 0.6 m voxels) sim:urban-hdl64 and sim:campus-os1 are as accurate as at 20000 and
  /// kitti_raw_0027_first60 more (docs/benchmarks.md, "Speed on recorded frames").
  std::uint32_t max_downsampled_points = 15000;
  /// ctf-icp, sparse frames (as above): the map receives the frame filtered at voxel_size / 4,
  /// not the registration's points. A 0.5 m map voxel on a plane gets at most about 4 points of a
  /// 0.25 m-filtered frame, fewer than the 5 the fine stage needs: keyframes that turn into new
  /// view would pair a tenth of their points (docs/odometry.md, "Recorded Avia keyframes").
  /// Off by default: it helps avia_hku1 and dynamic-outdoor-fast but not dynamic-outdoor.
  bool dense_sparse_map = false;
  int threads = 1;
  RegistrationOptions registration;  ///< parameters of the frame-to-frame baselines
};

/// Throws Error naming the first invalid field (unknown method, non-positive sizes, ...).
void check_odometry_config(const OdometryConfig& config);

/// "ctf-icp, icp, ...": the odometry's methods (ctf-icp and every registration method).
std::string odometry_method_list();
/// ctf-icp or a registration method (optional peers: frame_odometry.hpp).
bool is_odometry_method(const std::string& name);

}  // namespace scanmatch
