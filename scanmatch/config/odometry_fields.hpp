#pragma once
// The 3D odometry's options (OdometryConfig), described once (the protocol: fields.hpp).
#include "scanmatch/config/registration_fields.hpp"
#include "scanmatch/odometry/odometry_config.hpp"

namespace scanmatch {

template <typename Visitor>
void describe(OdometryConfig& c, Visitor& v) {
  v("method", c.method, "--method", "ctf-icp or a registration method, frame to frame");
  v("voxel_size", c.voxel_size, "--voxel", "Downsampling voxel of every frame, m (0: none)");
  v("min_range", c.min_range, "--min-range", "Nearer points are dropped, m");
  v("max_range", c.max_range, "--max-range", "Farther points are dropped, m");
  v("elevation_correction_deg", c.elevation_correction_deg, "--elevation-correction",
    "Lower every point's elevation by this many degrees first (a beam calibration error)");
  v("elevation_estimate", c.elevation_estimate, "--no-elevation-estimate",
    "Do not estimate a beam elevation bias from the first moving frames (without "
    "--elevation-correction, a clear one is taken out of the frames after them)");
  v("ndt_resolution", c.ndt_resolution, "--ndt-resolution",
    "ctf-icp: the coarse stage's NDT grid of the previous frame, m");
  v("ndt_neighbours", c.ndt_neighbours, nullptr, "ctf-icp coarse: voxels per point");
  v("coarse_voxel_size", c.coarse_voxel_size, nullptr, "ctf-icp: downsampling of the NDT source");
  v("max_coarse_points", c.max_coarse_points, nullptr,
    "ctf-icp: a denser NDT source is thinned further, to about this many points (0: no limit)");
  v("coarse_max_iterations", c.coarse_max_iterations, "--coarse-max-iterations",
    "ctf-icp: the coarse NDT stage's iteration limit");
  v("coarse_tolerance", c.coarse_tolerance, nullptr,
    "ctf-icp: the coarse stage's update tolerance");
  v("map_voxel_size", c.map_voxel_size, "--map-voxel",
    "ctf-icp: the global Gaussian map's voxel, m");
  v("merge_threshold", c.merge_threshold, "--merge-threshold",
    "ctf-icp: new points a map voxel collects before it is merged");
  v("map_radius", c.map_radius, "--map-radius",
    "ctf-icp: map voxels farther than this are dropped, m");
  v("map_voxel_min_points", c.map_voxel_min_points, nullptr, "points a map voxel needs to be used");
  v("map_voxel_max_points", c.map_voxel_max_points, nullptr, "points after which a voxel freezes");
  v("fine_max_iterations", c.fine_max_iterations, "--fine-max-iterations",
    "ctf-icp: the fine stage's Gauss-Newton steps");
  v("fine_tolerance", c.fine_tolerance, nullptr, "ctf-icp: the fine stage's update tolerance");
  v("fine_max_flatness", c.fine_max_flatness, nullptr, "ctf-icp: flattest map voxels used");
  v("fine_kernel_distance", c.fine_kernel_distance, nullptr, "ctf-icp: Cauchy kernel distance, m");
  v("degeneracy_guard_ratio", c.degeneracy_guard_ratio, "--degeneracy-guard-ratio",
    "ctf-icp: no fine-stage update along directions below this scaled eigenvalue ratio (0: off)");
  v("degeneracy_guard_frames", c.degeneracy_guard_frames, "--degeneracy-guard-frames",
    "ctf-icp: over this many first frames the guard uses degeneracy_ratio");
  v("degeneracy_ratio", c.degeneracy_ratio, "--degeneracy-ratio",
    "ctf-icp: scaled eigenvalue ratio below which a direction is reported degenerate (0: never)");
  v("fine_stage", c.fine_stage, "--no-fine", "Ablation: ctf-icp's coarse NDT stage only");
  v("map_update", c.map_update, "--no-map-update",
    "Ablation: ctf-icp's fine stage against the previous frame, no global map");
  v("constant_velocity", c.constant_velocity, nullptr, "constant-velocity motion prior");
  v("deskew", c.deskew, "--no-deskew", "Do not correct motion distortion");
  v("deskew_min_translation", c.deskew_min_translation, nullptr, "deskew dead band, m per frame");
  v("deskew_min_rotation", c.deskew_min_rotation, nullptr, "deskew dead band, rad per frame");
  v("redeskew_translation", c.redeskew_translation, nullptr,
    "deskew again by the registered motion where it misses the prior by this, m per frame");
  v("redeskew_rotation", c.redeskew_rotation, nullptr,
    "likewise for rotation, rad per frame (both 0: never)");
  v("spin_times", c.spin_times, "--spin-times",
    "Frames without point times (a spinning LiDAR's raw sweeps, e.g. KITTI raw .bin): derive each "
    "point's time from its azimuth, so they are deskewed");
  v("spin_period", c.spin_period, nullptr, "spin_times: s per turn of the sensor");
  v("spin_start_azimuth", c.spin_start_azimuth, nullptr,
    "spin_times: azimuth where each sweep starts, rad (atan2(y, x); 0: along +x)");
  v("spin_clockwise", c.spin_clockwise, nullptr,
    "spin_times: the sensor turns clockwise seen from above (azimuth decreasing with time)");
  v("anchor_min_translation", c.anchor_min_translation, nullptr,
    "the first motion's translation anchors the world (frame 0's start) above this, m per frame");
  v("anchor_min_rotation", c.anchor_min_rotation, nullptr,
    "likewise for its rotation, rad per frame");
  v("max_jump", c.max_jump, nullptr, "results farther from the prior are rejected, m");
  v("max_jump_angle", c.max_jump_angle, nullptr, "likewise for rotation, rad");
  v("time_scaled_prior", c.time_scaled_prior, nullptr,
    "scale the constant-velocity prior by the ratio of the frame time steps");
  v("max_step_ratio", c.max_step_ratio, nullptr,
    "time-step ratios beyond this (or its inverse) make the prior uncertain");
  v("prior_miss_distance", c.prior_miss_distance, nullptr,
    "an estimate this far from its prior makes the next prior uncertain, m");
  v("prior_miss_angle", c.prior_miss_angle, nullptr, "likewise for rotation, rad");
  v("uncertain_rotation", c.uncertain_rotation, nullptr,
    "a prior that turns more than this in one step is uncertain, rad");
  v("uncertain_starts", c.uncertain_starts, nullptr,
    "ctf-icp, uncertain prior: also try the identity, half and twice the prior motion and the "
    "prior turned about the sensor's z axis");
  v("rotation_starts", c.rotation_starts, nullptr,
    "ctf-icp, uncertain prior: turned starts per side, +-k * rotation_start_step (0: none)");
  v("rotation_start_step", c.rotation_start_step, nullptr,
    "ctf-icp: angle between turned starts, rad");
  v("uncertain_ndt_scale", c.uncertain_ndt_scale, nullptr,
    "ctf-icp: those starts run first on an NDT grid this many times ndt_resolution");
  v("start_voxel_size", c.start_voxel_size, nullptr,
    "ctf-icp: the descent on the wider grid takes the coarse points downsampled to this (m; at "
    "most coarse_voxel_size: no further downsampling)");
  v("wide_start_iterations", c.wide_start_iterations, nullptr,
    "ctf-icp: a certain prior whose NDT solve took this many iterations also starts on the wider "
    "grid (uncertain_ndt_scale), kept when it scores better (0: never)");
  v("start_screen_points", c.start_screen_points, nullptr,
    "ctf-icp, uncertain prior: the other starts are first solved and ranked on about this many "
    "coarse points (0: every start solved on every point; 150 is 2-5x cheaper on recorded "
    "keyframes, see docs/benchmarks.md)");
  v("start_full_solves", c.start_full_solves, nullptr,
    "ctf-icp: only this many best-ranked starts that beat the prior's result on that subset are "
    "then solved on every point");
  v("uncertain_jump_scale", c.uncertain_jump_scale, nullptr,
    "max_jump and max_jump_angle widen by this factor under an uncertain prior");
  v("global_start_below", c.global_start_below, nullptr,
    "ctf-icp, the first motion: where less than this share of the frame lies within 0.5 m of the "
    "first frame, it is also registered onto it with no prior (FPFH features), kept where "
    "global_start_gain times as much of it overlaps (0: off)");
  v("global_start_gain", c.global_start_gain, nullptr,
    "ctf-icp: how many times more of the frame the global start's result must overlap the first "
    "frame with to replace the local result");
  v("min_downsampled_points", c.min_downsampled_points, nullptr,
    "sparse frames (below 10x this) keeping fewer points get smaller voxels, to voxel_size / 4 "
    "(0: off)");
  v("max_downsampled_points", c.max_downsampled_points, nullptr,
    "frames keeping more points after the voxel filter are filtered at a larger voxel, learned "
    "from the last such frame, that keeps under this many (0: no limit)");
  v("dense_sparse_map", c.dense_sparse_map, nullptr,
    "ctf-icp, sparse frames: the map gets the frame at voxel_size / 4, so one keyframe makes "
    "usable map voxels");
  v("threads", c.threads, "--threads", "Threads (1 for fair comparisons)");
  v.nested("registration", c.registration);
}

}  // namespace scanmatch
