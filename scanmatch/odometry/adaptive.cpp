#include "scanmatch/odometry/adaptive.hpp"

#include <cmath>
#include <vector>

#include "scanmatch/geometry/voxel_filter.hpp"
#include "scanmatch/registration/factors/ndt.hpp"

namespace scanmatch {
namespace {

/// Time-step ratios this close to 1 count as regular: timestamp jitter is not motion.
constexpr double kRegularStep = 0.05;
/// Fewer NDT inliers than this make a coarse result unusable (as in register_ctf).
constexpr std::size_t kMinimumInliers = 20;
/// Another start replaces the plain coarse result only when its NDT score is better by this
/// fraction: starts that reach the same optimum never move a pose.
constexpr double kScoreMargin = 0.01;
/// Frames with this many times min_downsampled_points before the voxel filter are dense.
constexpr std::size_t kDenseFactor = 10;

Pose scaled(const Pose& motion, double factor) {
  return se3_exp(factor * se3_log(motion));
}

bool near(const Pose& a, const Pose& b) {
  const Pose d = a.inverse() * b;
  return d.translation().norm() < 0.05 && rotation_angle(d) < 0.01;
}

}  // namespace

MotionPrior predict_motion(const AdaptiveState& state, const Pose& velocity, double step,
                           std::size_t frames, const OdometryConfig& config) {
  MotionPrior prior;
  prior.motion = velocity;
  if (!config.constant_velocity) return prior;  // the previous pose is the guess, as before
  // Frame 1 has no motion yet (the identity), and a bridged frame's motion was not measured.
  prior.uncertain = frames == 1 || state.previous_bridged || state.previous_missed;
  if (!config.time_scaled_prior || frames < 2) return prior;
  if (!(step > 0.0) || !(state.velocity_period > 0.0)) {
    prior.uncertain = true;  // no usable stamps: the step is unknown
    return prior;
  }
  const double ratio = step / state.velocity_period;
  if (std::abs(ratio - 1.0) <= kRegularStep) return prior;
  if (ratio > config.max_step_ratio || ratio < 1.0 / config.max_step_ratio) {
    // A gap (dropped frames) or a burst: scale within bounds, but trust it less.
    prior.uncertain = true;
    prior.scale = std::clamp(ratio, 1.0 / config.max_step_ratio, config.max_step_ratio);
  } else {
    prior.scale = ratio;
  }
  prior.motion = scaled(velocity, prior.scale);
  return prior;
}

void record_motion(AdaptiveState& state, const Pose& estimated, bool bridged, double step,
                   const OdometryConfig& config) {
  const Pose miss = state.prior.motion.inverse() * estimated;
  state.previous_missed = !bridged && (miss.translation().norm() > config.prior_miss_distance ||
                                       rotation_angle(miss) > config.prior_miss_angle);
  state.previous_bridged = bridged;
  if (!bridged) state.velocity_period = step > 0.0 ? step : state.velocity_period;
}

double jump_gate_scale(const AdaptiveState& state, const OdometryConfig& config) {
  return state.prior.uncertain ? config.uncertain_jump_scale : 1.0;
}

Pose coarse_multi_start(const PointCloud& source, const PointCloud& previous,
                        const GaussianVoxelMap& previous_ndt, const Pose& plain,
                        const Pose& prior_motion, const SolverOptions& solver,
                        const OdometryConfig& config, int& iterations) {
  if (!config.uncertain_starts || previous.empty() || previous_ndt.size() == 0) return plain;
  const double outliers = config.registration.ndt_outlier_ratio;
  double d1 = 0.0, d2 = 0.0;
  ndt_score_constants(config.ndt_resolution, outliers, d1, d2);
  const NdtFactor normal{source, previous_ndt, config.ndt_neighbours, d1, d2};
  SolverOptions scoring = solver;
  scoring.num_threads = solver.num_threads;
  const auto score = [&](const Pose& motion, std::size_t& inliers) {
    const LinearSystem s = linearize_all(normal, motion, scoring);
    inliers = s.inliers;
    return s.cost;  // the NDT score: negative, lower is better
  };
  std::size_t inliers = 0;
  double best_cost = score(plain, inliers);
  Pose best = plain;

  // The wider grid of the previous frame: a basin a few times the normal one.
  GaussianVoxelMapOptions wide_options;
  wide_options.voxel_size = config.ndt_resolution * config.uncertain_ndt_scale;
  GaussianVoxelMap wide(wide_options);
  wide.insert(previous);
  double w1 = 0.0, w2 = 0.0;
  ndt_score_constants(wide_options.voxel_size, outliers, w1, w2);
  const NdtFactor coarse{source, wide, config.ndt_neighbours, w1, w2};

  std::vector<Pose> tried;
  for (const Pose& start : {prior_motion, Pose(Pose::Identity()), scaled(prior_motion, 0.5),
                            scaled(prior_motion, 2.0)}) {
    bool seen = false;
    for (const Pose& t : tried) seen = seen || near(t, start);
    if (seen) continue;
    tried.push_back(start);
    const RegistrationResult widened = optimize(coarse, start, solver);
    iterations += widened.iterations;
    if (widened.inliers < kMinimumInliers || !to_matrix(widened.transform).allFinite()) continue;
    const RegistrationResult refined = optimize(normal, widened.transform, solver);
    iterations += refined.iterations;
    if (!to_matrix(refined.transform).allFinite()) continue;
    const double cost = score(refined.transform, inliers);
    if (inliers >= kMinimumInliers && cost < best_cost - kScoreMargin * std::abs(best_cost)) {
      best_cost = cost;
      best = refined.transform;
    }
  }
  return best;
}

PointCloud adaptive_downsample(const PointCloud& cloud, std::size_t delivered,
                               const OdometryConfig& config) {
  if (config.voxel_size <= 0.0) return cloud;
  double voxel = config.voxel_size;
  PointCloud down = voxel_downsample(cloud, voxel);
  // Only frames delivered sparse (FAST-LIO keyframes): a dense frame that keeps few points sees a
  // near wall or is mostly within min_range, and finer voxels there did not help (dynamic-indoor:
  // 0.1864 -> 0.1878 % ATE when applied to those frames too).
  if (delivered >= kDenseFactor * config.min_downsampled_points) return down;
  // Halve the voxel (twice at most) while a sparse frame keeps too few points to register.
  for (int k = 0;
       k < 2 && down.size() < config.min_downsampled_points && down.size() < cloud.size(); ++k) {
    voxel *= 0.5;
    down = voxel_downsample(cloud, voxel);
  }
  return down;
}

}  // namespace scanmatch
