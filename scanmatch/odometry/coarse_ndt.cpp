#include "scanmatch/odometry/coarse_ndt.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "scanmatch/geometry/voxel_filter.hpp"
#include "scanmatch/odometry/frame_odometry.hpp"
#include "scanmatch/registration/factors/ndt.hpp"

namespace scanmatch {
namespace {

/// Another start replaces the plain result only when its NDT score is better by this fraction:
/// starts that reach the same optimum never move a pose.
constexpr double kScoreMargin = 0.01;

GaussianVoxelMapOptions grid_options(double resolution) {
  GaussianVoxelMapOptions o;
  o.voxel_size = resolution;
  return o;
}

/// The NDT factor of `source` on `grid`, with a voxel hint per point when each point looks up one
/// voxel: every solve and score on the factor then skips the hash probe of a point whose voxel
/// has not changed since the last (results do not change).
NdtFactor hinted_factor(const PointCloud& source, const GaussianVoxelMap& grid,
                        const OdometryConfig& config) {
  NdtFactor factor =
      ndt_factor(source, grid, config.ndt_neighbours, config.registration.ndt_outlier_ratio);
  if (config.ndt_neighbours == 1) factor.hints.resize(source.size());
  return factor;
}

bool near(const Pose& a, const Pose& b) {
  const Pose d = a.inverse() * b;
  return d.translation().norm() < 0.05 && rotation_angle(d) < 0.01;
}

}  // namespace

CoarseNdt::CoarseNdt(const OdometryConfig& config)
    : config_(config), grid_(grid_options(config.ndt_resolution)) {
  solver_ = config.registration.solver;
  solver_.max_iterations = config.coarse_max_iterations;
  solver_.rotation_tolerance = solver_.translation_tolerance = config.coarse_tolerance;
  solver_.kernel = RobustKernel{};
  // The fine stage re-linearises anyway: the coarse result needs no pass at its final pose.
  solver_.final_linearization = false;
}

CoarseResult CoarseNdt::align(const PointCloud& frame, const MotionPrior& prior) const {
  CoarseResult result;
  result.motion = prior.motion;
  if (grid_.size() == 0) return result;
  // A sparser cloud: the stage only has to bring the fine stage into its basin.
  const PointCloud sparser = config_.coarse_voxel_size > config_.voxel_size
                                 ? voxel_downsample(frame, config_.coarse_voxel_size)
                                 : PointCloud{};
  const PointCloud& source = sparser.empty() ? frame : sparser;
  const NdtFactor factor = hinted_factor(source, grid_, config_);
  const RegistrationResult plain = optimize(factor, prior.motion, solver_);
  result.iterations = plain.iterations;
  result.condition_number = plain.condition_number;
  result.registered = plain.inliers >= kMinimumFramePoints;
  if (result.registered) result.motion = plain.transform;
  // A certain prior whose solve was slow to settle may have stopped in a ripple of the grid.
  const bool slow =
      config_.wide_start_iterations > 0 && plain.iterations >= config_.wide_start_iterations;
  if (prior.uncertain || slow)
    result.motion = best_start(source, result.motion, prior.motion, prior.uncertain,
                               result.iterations, result.screen_iterations, result.recovered);
  return result;
}

std::vector<Pose> CoarseNdt::other_starts(const Pose& prior_motion, bool uncertain) const {
  if (!uncertain) return {prior_motion};
  std::vector<Pose> starts = {prior_motion, Pose(Pose::Identity()),
                              scaled_motion(prior_motion, 0.5), scaled_motion(prior_motion, 2.0)};
  // About the sensor's z axis: sensors are mounted upright, and hand-held ones sweep mostly about
  // the vertical. (The prior's own axis was tried: avia_hku1 1.5 % against 0.16 %.)
  for (int k = 1; k <= config_.rotation_starts; ++k)
    for (const double side : {-1.0, 1.0}) {
      Pose turned = prior_motion;
      turned.linear() =
          prior_motion.linear() *
          Eigen::AngleAxisd(side * k * config_.rotation_start_step, Eigen::Vector3d::UnitZ())
              .toRotationMatrix();
      starts.push_back(turned);
    }
  return starts;
}

Pose CoarseNdt::best_start(const PointCloud& source, const Pose& plain, const Pose& prior_motion,
                           bool uncertain, int& iterations, int& screen_iterations,
                           bool& recovered) const {
  if ((uncertain && !config_.uncertain_starts) || reference_.empty()) return plain;
  const NdtFactor normal = hinted_factor(source, grid_, config_);
  const auto score = [&](const Pose& motion, std::size_t& inliers) {
    const LinearSystem s = linearize_all(normal, motion, solver_);
    inliers = s.inliers;
    return s.cost;  // the NDT score: negative, lower is better
  };
  std::size_t inliers = 0;
  double best_cost = score(plain, inliers);
  Pose best = plain;

  // The wider grid of the reference frame: a basin a few times the normal one. Built once per
  // reference, on first use.
  if (!wide_grid_) {
    wide_grid_.emplace(grid_options(config_.ndt_resolution * config_.uncertain_ndt_scale));
    wide_grid_->insert(reference_);
  }
  const NdtFactor widened_factor = hinted_factor(source, *wide_grid_, config_);

  std::vector<Pose> starts;
  for (const Pose& start : other_starts(prior_motion, uncertain)) {
    bool seen = false;
    for (const Pose& t : starts) seen = seen || near(t, start);
    if (!seen) starts.push_back(start);
  }
  // Each start solved on every point from its own pose: the old way, and the fallback.
  bool from_wide_grid = true;
  if (should_screen(starts.size(), source.size()))
    starts = screened_starts(source, starts, plain, screen_iterations, from_wide_grid);

  for (const Pose& start : starts) {
    Pose refined_start = start;
    if (from_wide_grid) {
      const RegistrationResult widened = optimize(widened_factor, start, solver_);
      iterations += widened.iterations;
      if (widened.inliers < kMinimumFramePoints || !to_matrix(widened.transform).allFinite())
        continue;
      refined_start = widened.transform;
    }
    const RegistrationResult refined = optimize(normal, refined_start, solver_);
    iterations += refined.iterations;
    if (!to_matrix(refined.transform).allFinite()) continue;
    const double cost = score(refined.transform, inliers);
    if (inliers >= kMinimumFramePoints && cost < best_cost - kScoreMargin * std::abs(best_cost)) {
      best_cost = cost;
      best = refined.transform;
      recovered = true;
    }
  }
  return best;
}

bool CoarseNdt::should_screen(std::size_t start_count, std::size_t source_points) const {
  return config_.start_screen_points > 0 && config_.start_full_solves > 0 &&
         start_count > static_cast<std::size_t>(config_.start_full_solves) &&
         source_points >= 2 * config_.start_screen_points &&
         config_.start_screen_points >= 2 * kMinimumFramePoints;
}

std::vector<Pose> CoarseNdt::screened_starts(const PointCloud& source,
                                             const std::vector<Pose>& starts, const Pose& plain,
                                             int& screen_iterations, bool& from_wide_grid) const {
  // Every stride-th point: the source is already one point per coarse voxel, so the subset stays
  // spread over the scene.
  const std::size_t stride = source.size() / config_.start_screen_points;
  std::vector<std::size_t> kept;
  for (std::size_t i = 0; i < source.size(); i += stride) kept.push_back(i);
  const PointCloud subset = select(source, kept);
  const NdtFactor normal = hinted_factor(subset, grid_, config_);
  const NdtFactor widened = hinted_factor(subset, *wide_grid_, config_);
  const auto subset_cost = [&](const Pose& motion) {
    const LinearSystem s = linearize_all(normal, motion, solver_);
    return s.inliers >= kMinimumFramePoints ? s.cost : 0.0;
  };
  // Only starts that beat the plain result on the subset are worth a solve on every point.
  const double plain_cost = subset_cost(plain);
  std::vector<std::pair<double, Pose>> ranked;
  for (const Pose& start : starts) {
    const RegistrationResult wide = optimize(widened, start, solver_);
    screen_iterations += wide.iterations;
    if (!to_matrix(wide.transform).allFinite()) continue;
    const RegistrationResult result = optimize(normal, wide.transform, solver_);
    screen_iterations += result.iterations;
    // Not skipped when near the plain result: on recorded keyframes the plain solve often stops a
    // centimetre or two short, and the solve from the screened pose gets there (avia_hku1: ATE
    // 0.11 % of the path with them skipped, 0.075 % kept).
    if (!to_matrix(result.transform).allFinite()) continue;
    const double cost = subset_cost(result.transform);
    if (cost < plain_cost) ranked.emplace_back(cost, result.transform);
  }
  std::sort(ranked.begin(), ranked.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<Pose> best;
  for (const auto& [cost, motion] : ranked) {
    if (best.size() >= static_cast<std::size_t>(config_.start_full_solves)) break;
    bool seen = false;
    for (const Pose& b : best) seen = seen || near(b, motion);
    if (!seen) best.push_back(motion);
  }
  // The screened poses are already in the normal grid's basin.
  from_wide_grid = false;
  return best;
}

void CoarseNdt::set_reference(PointCloud frame, bool bridged) {
  grid_.clear();
  grid_.insert(frame);
  if (!frame.empty() || !bridged) {
    reference_ = std::move(frame);
    wide_grid_.reset();
  }
}

}  // namespace scanmatch
