#include "scanmatch/odometry/odometry.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <optional>

#include "scanmatch/core/error.hpp"
#include "scanmatch/geometry/voxel_filter.hpp"
#include "scanmatch/odometry/adaptive.hpp"
#include "scanmatch/registration/factors/ctf_fine.hpp"
#include "scanmatch/registration/factors/ndt.hpp"

namespace scanmatch {
namespace {
using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

GaussianVoxelMapOptions map_options(const OdometryConfig& c) {
  GaussianVoxelMapOptions o;
  o.voxel_size = c.map_voxel_size;
  o.merge_threshold = c.merge_threshold;
  o.planar_epsilon = c.registration.ctf_epsilon;
  o.max_points = c.map_voxel_max_points;
  o.min_points = c.map_voxel_min_points;
  o.distributions = false;  // the fine stage reads means and normals only
  return o;
}

GaussianVoxelMapOptions ndt_options(const OdometryConfig& c) {
  GaussianVoxelMapOptions o;
  o.voxel_size = c.ndt_resolution;
  return o;
}

}  // namespace

bool is_odometry_method(const std::string& name) {
  return name == "ctf-icp" || is_registration_method(name);
}

std::string odometry_method_list() {
  return "ctf-icp, " + registration_method_list();
}

namespace {

void check_config(const OdometryConfig& c) {
  if (!is_odometry_method(c.method))
    throw Error("unknown odometry method '" + c.method + "' (valid: " + odometry_method_list() +
                ")");
  const auto positive = [](double v, const char* name) {
    if (!(v > 0.0) || !std::isfinite(v))
      throw Error(std::string("odometry: ") + name + " must be positive");
  };
  positive(c.ndt_resolution, "ndt_resolution");
  positive(c.map_voxel_size, "map_voxel_size");
  positive(c.map_radius, "map_radius");
  positive(c.max_range, "max_range");
  positive(c.coarse_tolerance, "coarse_tolerance");
  if (c.voxel_size < 0.0 || c.coarse_voxel_size < 0.0 || c.min_range < 0.0)
    throw Error("odometry: voxel sizes and min_range must not be negative");
  if (c.merge_threshold == 0) throw Error("odometry: merge_threshold must be at least 1");
  if (c.threads < 1) throw Error("odometry: threads must be at least 1");
  if (!(c.max_step_ratio >= 1.0)) throw Error("odometry: max_step_ratio must be at least 1");
  if (!(c.uncertain_ndt_scale >= 1.0) || !(c.uncertain_jump_scale >= 1.0))
    throw Error("odometry: uncertain_ndt_scale and uncertain_jump_scale must be at least 1");
  positive(c.prior_miss_distance, "prior_miss_distance");
  positive(c.prior_miss_angle, "prior_miss_angle");
}

// Deskewing with the constant-velocity motion over the frame, into the sensor frame at the
// reference time `reference` (s after the frame start). The transform at each of `bins` instants is
// exact; between them a first-order step (I + ds xi^) is accurate to O(ds^2 |w|^2).
class FrameMotion {
 public:
  FrameMotion(const Pose& motion, double period, double max_time, double reference)
      : xi_(se3_log(motion) / period),
        angular_(xi_.head<3>().cast<float>()),
        linear_(xi_.tail<3>().cast<float>()) {
    step_ = std::max(max_time, 1e-6) / (kBins - 1);
    for (int k = 0; k < kBins; ++k)
      bins_[k] = se3_exp(xi_ * (k * step_ - reference)).matrix().cast<float>();
  }
  Point apply(const Point& p, float t) const {
    // Rounding by truncation (not std::lround, a library call per point): equal for t >= 0, and
    // the clamp maps any negative time to the first bin either way.
    const int k = std::clamp(static_cast<int>(t / step_ + 0.5), 0, kBins - 1);
    const float ds = t - static_cast<float>(k * step_);
    const Point q = p + ds * (angular_.cross(p) + linear_);
    return bins_[k].topLeftCorner<3, 3>() * q + bins_[k].topRightCorner<3, 1>();
  }

 private:
  static constexpr int kBins = 64;
  Vector6d xi_;                       ///< twist per second
  Eigen::Vector3f angular_, linear_;  ///< its halves in float, for the per-point step
  double step_;
  Eigen::Matrix4f bins_[kBins];
};
}  // namespace

Odometry::Odometry(const OdometryConfig& config)
    : config_(config), map_(map_options(config)), previous_ndt_(ndt_options(config)) {
  check_config(config);
  config_.registration.solver.num_threads = config.threads;
  ndt_score_constants(config.ndt_resolution, config.registration.ndt_outlier_ratio, ndt_d1_,
                      ndt_d2_);
}

bool Odometry::moving(const Pose& motion, double factor) const {
  return motion.translation().norm() >= factor * config_.deskew_min_translation ||
         rotation_angle(motion) >= factor * config_.deskew_min_rotation;
}

PointCloud Odometry::preprocess(const PointCloud& frame) const {
  const double min2 = config_.min_range * config_.min_range,
               max2 = config_.max_range * config_.max_range;
  const bool deskew = config_.deskew && frame.has_time() && frames_ > 1 && moving(velocity_);
  float max_time = 0.0f;
  if (deskew)
    for (float t : frame.time)
      if (std::isfinite(t)) max_time = std::max(max_time, t);
  std::optional<FrameMotion> motion;
  if (deskew) motion.emplace(adaptive_.prior.motion, frame_period_, max_time, 0.5 * frame_period_);
  // Rings and intensities feed the feature methods (loam); ctf-icp reads only the points, and
  // times are used up by the deskew.
  const bool keep_ring = frame.has_ring() && config_.method != "ctf-icp";
  const bool keep_intensity = frame.has_intensity() && config_.method != "ctf-icp";
  PointCloud kept;
  kept.points.reserve(frame.size());
  for (std::size_t i = 0; i < frame.size(); ++i) {
    const Point& p = frame.points[i];
    const double r2 = p.squaredNorm();
    if (!p.allFinite() || r2 < min2 || r2 > max2) continue;
    if (deskew && std::isfinite(frame.time[i]))
      kept.points.push_back(motion->apply(p, frame.time[i]));
    else
      kept.points.push_back(p);
    if (keep_ring) kept.ring.push_back(frame.ring[i]);
    if (keep_intensity) kept.intensity.push_back(frame.intensity[i]);
  }
  return adaptive_downsample(kept, frame.size(), config_);
}

Pose Odometry::register_baseline(const PointCloud& down, const Pose& predicted) {
  if (down.size() < minimum_points(config_.method, config_.registration) ||
      previous_.size() < minimum_points(config_.method, config_.registration)) {
    stats_.bridged = true;
    return predicted;
  }
  const auto start = Clock::now();
  RegistrationOptions o = config_.registration;
  o.method = config_.method;
  const RegistrationResult r = register_clouds(down, previous_, o, adaptive_.prior.motion);
  stats_.coarse_ms = ms_since(start);
  stats_.iterations = r.iterations;
  stats_.condition_number = r.condition_number;
  return pose_ * r.transform;
}

Pose Odometry::register_ctf(const PointCloud& down, const PointCloud& coarse_source,
                            const Pose& predicted) {
  constexpr std::size_t kMinimumPoints = 20;
  if (down.size() < kMinimumPoints) {
    stats_.bridged = true;
    return predicted;
  }
  // Coarse: NDT frame-to-frame, the increment from the previous frame starting at the prior.
  const auto coarse_start = Clock::now();
  Pose estimate = predicted;
  if (previous_ndt_.size() > 0) {
    SolverOptions solver = config_.registration.solver;
    solver.max_iterations = config_.coarse_max_iterations;
    solver.rotation_tolerance = solver.translation_tolerance = config_.coarse_tolerance;
    solver.kernel = RobustKernel{};
    // The fine stage re-linearises anyway: the coarse result needs no pass at its final pose.
    solver.final_linearization = false;
    NdtFactor factor{coarse_source, previous_ndt_, config_.ndt_neighbours, ndt_d1_, ndt_d2_};
    if (config_.ndt_neighbours == 1) factor.hints.resize(coarse_source.size());
    const RegistrationResult coarse = optimize(factor, adaptive_.prior.motion, solver);
    stats_.iterations = coarse.iterations;
    stats_.condition_number = coarse.condition_number;
    if (coarse.inliers >= kMinimumPoints) estimate = pose_ * coarse.transform;
    if (adaptive_.prior.uncertain)  // first frames, irregular steps: check other starts
      estimate =
          pose_ * coarse_multi_start(
                      coarse_source, previous_, previous_ndt_,
                      coarse.inliers >= kMinimumPoints ? coarse.transform : adaptive_.prior.motion,
                      adaptive_.prior.motion, solver, config_, stats_.iterations);
  }
  stats_.coarse_ms = ms_since(coarse_start);

  // Fine: frame-to-map on the planar Gaussians.
  if (config_.fine_stage && map_.size() > 0) {
    const auto fine_start = Clock::now();
    CtfFineOptions fine_options;
    fine_options.max_iterations = config_.fine_max_iterations;
    fine_options.tolerance = config_.fine_tolerance;
    fine_options.max_flatness = static_cast<float>(config_.fine_max_flatness);
    fine_options.with_cost = false;  // the odometry reads the pose, inliers and information
    SolverOptions& solver = fine_options.solver;
    solver = config_.registration.solver;
    solver.degeneracy_ratio = config_.degeneracy_ratio;
    // Rotations count as the displacement they cause at the frame's own RMS range: a fixed lever
    // would call a narrow corridor's well-constrained roll degenerate.
    double sum_r2 = 0.0;
    for (const Point& p : down.points) sum_r2 += p.squaredNorm();
    solver.degeneracy_range = std::max(std::sqrt(sum_r2 / static_cast<double>(down.size())), 0.1);
    solver.kernel = RobustKernel{};
    if (config_.fine_kernel_distance > 0.0) {
      // The residual is weighted by 1/eps along the normal: scale the kernel to match.
      solver.kernel.type = KernelType::kCauchy;
      solver.kernel.scale =
          config_.fine_kernel_distance / std::sqrt(config_.registration.ctf_epsilon);
    }
    const RegistrationResult fine = register_ctf_fine(down, map_, estimate, fine_options);
    if (fine.inliers >= kMinimumPoints) {
      estimate = fine.transform;
      stats_.degenerate_directions =
          analyse_degeneracy(fine.information, solver.degeneracy_range, solver.degeneracy_ratio)
              .directions;
    }
    stats_.fine_ms = ms_since(fine_start);
    stats_.iterations += fine.iterations;
    stats_.condition_number = fine.condition_number;
  }
  return estimate;
}

Pose Odometry::register_frame(const PointCloud& frame, double timestamp) {
  const auto start = Clock::now();
  stats_ = FrameStats{};
  stats_.points_in = frame.size();
  if (frames_ == 0) timed_frames_ = frame.has_time();
  const double step = frames_ > 0 ? timestamp - last_timestamp_ : 0.0;
  if (frames_ > 0 && timestamp > last_timestamp_) frame_period_ = timestamp - last_timestamp_;
  last_timestamp_ = timestamp;
  adaptive_.prior = predict_motion(adaptive_, velocity_, step, frames_, config_);
  PointCloud down = frame.fields_consistent()
                        ? preprocess(frame)
                        : PointCloud{};  // inconsistent fields: treated as an empty frame
  stats_.points_downsampled = down.size();
  stats_.preprocess_ms = ms_since(start);

  const Pose predicted = pose_ * adaptive_.prior.motion;
  const bool ctf = config_.method == "ctf-icp";
  // The NDT stage works on a sparser cloud: it only has to bring the fine stage into its basin.
  const PointCloud coarse = ctf && config_.coarse_voxel_size > config_.voxel_size
                                ? voxel_downsample(down, config_.coarse_voxel_size)
                                : PointCloud{};
  const PointCloud& coarse_cloud = coarse.empty() ? down : coarse;
  Pose estimate = predicted;
  if (frames_ > 0) {
    try {
      estimate =
          ctf ? register_ctf(down, coarse_cloud, predicted) : register_baseline(down, predicted);
    } catch (const Error&) {
      stats_.bridged = true;  // too few points or correspondences: keep the motion prior
      estimate = predicted;
    }
  }
  // Never let a failed solve poison the trajectory: a result far from the motion prior (or not
  // finite) is replaced by the prior.
  const Pose jump = predicted.inverse() * estimate;
  const double gate = jump_gate_scale(adaptive_, config_);
  if (!to_matrix(estimate).allFinite() || jump.translation().norm() > gate * config_.max_jump ||
      rotation_angle(jump) > gate * config_.max_jump_angle) {
    stats_.bridged = true;
    estimate = predicted;
  }
  estimate = orthonormalized(estimate);

  if (ctf) {
    const auto map_start = Clock::now();
    // --no-fine: nothing reads the global map, so it is not built (nor timed).
    if (config_.fine_stage && config_.map_update) {
      // Points beyond the radius would be pruned anyway: keep them out so the bound is strict.
      bool beyond = false;
      const double r2 = config_.map_radius * config_.map_radius;
      for (const Point& p : down.points) beyond = beyond || p.squaredNorm() > r2;
      map_.insert(beyond ? crop_range(down, 0.0, config_.map_radius) : down, estimate);
      if (frames_ == 0) map_.flush();  // the first frame builds the map at once
      // Pruning scans the whole map: do it once the sensor has moved a tenth of the radius.
      if ((estimate.translation() - last_prune_).norm() > 0.1 * config_.map_radius) {
        map_.remove_far(estimate.translation(), config_.map_radius);
        last_prune_ = estimate.translation();
      }
    } else if (config_.fine_stage && down.size() > 0) {
      // Ablation: the fine stage sees only the previous frame (no map building or update).
      map_.clear();
      map_.insert(down, estimate);
      map_.flush();
    }
    previous_ndt_.clear();
    previous_ndt_.insert(down);
    stats_.map_ms = ms_since(map_start);
  }
  // A bridged frame keeps the last good velocity rather than one derived from the prior itself.
  const Pose motion = frames_ > 0 ? orthonormalized(pose_.inverse() * estimate) : Pose::Identity();
  if (frames_ > 0) record_motion(adaptive_, motion, stats_.bridged, step, config_);
  if (!stats_.bridged && config_.constant_velocity) velocity_ = motion;
  pose_ = estimate;
  // The registration estimated the pose at mid-frame (the deskew reference, and the average of a
  // distorted frame's instants); the frame-start pose lies half the frame motion before it.
  // Keeping the mid-frame pose as the state matters: deskewing to the frame start would shift a
  // frame by half of any velocity error, and that error would feed back into the next velocity.
  Pose reported = pose_;
  if (timed_frames_ && frames_ > 0) {
    reported = pose_ * se3_exp(-0.5 * se3_log(velocity_));
    // The world is frame 0's start pose, which is known once the first motion is: half of it
    // before frame 0's mid-frame pose (the internal origin).
    // A first motion within a few times the deskew dead band is mostly the first registration's
    // noise (a still start): anchoring by it would offset every later pose.
    if (frames_ == 1 && moving(velocity_, 3.0))
      world_from_internal_ = se3_exp(0.5 * se3_log(velocity_));
    reported = world_from_internal_ * reported;
  }
  if (!down.empty() || !stats_.bridged) previous_ = std::move(down);
  ++frames_;
  stats_.total_ms = ms_since(start);
  return orthonormalized(reported);
}

}  // namespace scanmatch
