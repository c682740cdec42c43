#include "scanmatch/odometry/coarse_ndt.hpp"

#include <cmath>
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

bool near(const Pose& a, const Pose& b) {
  const Pose d = a.inverse() * b;
  return d.translation().norm() < 0.05 && rotation_angle(d) < 0.01;
}

}  // namespace

CoarseNdt::CoarseNdt(const OdometryConfig& config)
    : config_(config), grid_(grid_options(config.ndt_resolution)) {
  solver_ = config.registration.solver;
  solver_.num_threads = config.threads;
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
  NdtFactor factor =
      ndt_factor(source, grid_, config_.ndt_neighbours, config_.registration.ndt_outlier_ratio);
  if (config_.ndt_neighbours == 1) factor.hints.resize(source.size());
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
                               result.iterations, result.recovered);
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
                           bool uncertain, int& iterations, bool& recovered) const {
  if ((uncertain && !config_.uncertain_starts) || reference_.empty()) return plain;
  const double outliers = config_.registration.ndt_outlier_ratio;
  const NdtFactor normal = ndt_factor(source, grid_, config_.ndt_neighbours, outliers);
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
  const NdtFactor widened_factor =
      ndt_factor(source, *wide_grid_, config_.ndt_neighbours, outliers);

  std::vector<Pose> tried;
  for (const Pose& start : other_starts(prior_motion, uncertain)) {
    bool seen = false;
    for (const Pose& t : tried) seen = seen || near(t, start);
    if (seen) continue;
    tried.push_back(start);
    const RegistrationResult widened = optimize(widened_factor, start, solver_);
    iterations += widened.iterations;
    if (widened.inliers < kMinimumFramePoints || !to_matrix(widened.transform).allFinite())
      continue;
    const RegistrationResult refined = optimize(normal, widened.transform, solver_);
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

void CoarseNdt::set_reference(PointCloud frame, bool bridged) {
  grid_.clear();
  grid_.insert(frame);
  if (!frame.empty() || !bridged) {
    reference_ = std::move(frame);
    wide_grid_.reset();
  }
}

}  // namespace scanmatch
