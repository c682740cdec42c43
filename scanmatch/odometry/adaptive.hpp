#pragma once
// Adaptive rules of the odometry for sparse and irregular frames (FAST-LIO-style keyframe folders,
// spinning LiDARs sampled every few frames), with the default configuration:
//
// - Time-scaled motion prior: the constant-velocity prior scales the last motion by the ratio of
//   the frame time steps. The prior is *uncertain* for the first registered frame, when the time
//   stamps do not increase or their ratio is outside [1/max_step_ratio, max_step_ratio], after a
//   bridged frame, and after a frame whose estimate missed its prior by more than
//   prior_miss_distance / prior_miss_angle (irregular steps without time stamps).
// - Uncertain prior: the coarse stage also tries other starts (identity, half and twice the prior
//   motion), each first on a wider NDT grid of the previous frame, and keeps the one with the best
//   NDT score at the normal resolution; the jump gate widens by uncertain_jump_scale.
// - Sizes from the frame itself: a sparse frame (delivered with fewer than 10 x
//   min_downsampled_points points) that keeps fewer than min_downsampled_points after the voxel
//   filter is downsampled again with a smaller voxel (down to a quarter of voxel_size).
//
// With regular time steps, an accurate prior and dense frames none of this changes a pose.

#include <cstddef>

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/core/se3.hpp"
#include "scanmatch/geometry/gaussian_voxel_map.hpp"
#include "scanmatch/odometry/adaptive_state.hpp"
#include "scanmatch/odometry/odometry.hpp"
#include "scanmatch/registration/solver.hpp"

namespace scanmatch {

/// The prior of the next frame, `step` s after the last one (<= 0: no usable stamps), from the
/// last motion `velocity`; `frames` frames were registered before.
MotionPrior predict_motion(const AdaptiveState& state, const Pose& velocity, double step,
                           std::size_t frames, const OdometryConfig& config);

/// Records the frame's outcome: its prior against the estimated motion (`estimated` from the last
/// pose), whether it was bridged, and the time step it spanned.
void record_motion(AdaptiveState& state, const Pose& estimated, bool bridged, double step,
                   const OdometryConfig& config);

/// Jump gate factor for the frame (1, or uncertain_jump_scale with an uncertain prior).
double jump_gate_scale(const AdaptiveState& state, const OdometryConfig& config);

/// The coarse stage under an uncertain prior: `plain` is the normal NDT result (motion from the
/// last frame, started at the prior) of `source` against `previous_ndt` (built from `previous`);
/// returns the best-scoring motion among it and the other starts, and adds their iterations.
Pose coarse_multi_start(const PointCloud& source, const PointCloud& previous,
                        const GaussianVoxelMap& previous_ndt, const Pose& plain,
                        const Pose& prior_motion, const SolverOptions& solver,
                        const OdometryConfig& config, int& iterations);

/// The voxel filter with the point floor: `voxel_size`, then, for a frame delivered with fewer than
/// 10 x min_downsampled_points points (`delivered`, before the range crop), smaller voxels while
/// fewer than min_downsampled_points remain (at most down to voxel_size / 4).
PointCloud adaptive_downsample(const PointCloud& cloud, std::size_t delivered,
                               const OdometryConfig& config);

}  // namespace scanmatch
