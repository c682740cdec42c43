// PCL's ICP, NDT and GICP as frame-to-frame odometry peers (`--method pcl-icp`, `pcl-ndt`,
// `pcl-gicp`), built with -DSCANMATCH_WITH_PCL=ON. They see what our frame-to-frame baselines see:
// the frame through our Preprocessor (range crop, voxel_size with the sparse-frame point floor, no
// deskew), registered to the previous frame from the constant-velocity guess, with the settings of
// the pair benchmark
// (bench/pcl/bench_pcl.cpp). A registration that does not converge or leaves the prior by more
// than max_jump / max_jump_angle is bridged by the prior, as ours are.

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/gicp.h>
#include <pcl/registration/icp.h>
#include <pcl/registration/ndt.h>

#include <chrono>
#include <memory>

#include "scanmatch/odometry/frame_odometry.hpp"
#include "scanmatch/odometry/preprocessor.hpp"

namespace scanmatch {
namespace {

using Clock = std::chrono::steady_clock;
using Cloud = pcl::PointCloud<pcl::PointXYZ>;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

Cloud::Ptr to_pcl(const PointCloud& cloud) {
  auto out = std::make_shared<Cloud>();
  out->reserve(cloud.size());
  for (const Point& p : cloud.points) out->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  return out;
}

enum class PclMethod { kIcp, kNdt, kGicp };

class PclOdometry final : public FrameOdometry {
 public:
  PclOdometry(const OdometryConfig& config, PclMethod method)
      : config_(config), method_(method), preprocessor_(preprocess_options(config, false)) {}

  Pose register_frame(const PointCloud& frame, double) override {
    const auto start = Clock::now();
    stats_ = FrameStats{};
    stats_.points_in = frame.size();
    PointCloud down = preprocessor_.process(frame);
    stats_.points_downsampled = down.size();
    stats_.preprocess_ms = ms_since(start);

    Pose motion = velocity_;
    const bool first = !previous_;
    Cloud::Ptr current = to_pcl(down);
    if (!first && down.size() >= kMinimumFramePoints && previous_->size() >= kMinimumFramePoints) {
      const auto coarse_start = Clock::now();
      const Pose estimate = align(current, velocity_);
      stats_.coarse_ms = ms_since(coarse_start);
      const Pose jump = velocity_.inverse() * estimate;
      if (converged_ && to_matrix(estimate).allFinite() &&
          jump.translation().norm() <= config_.max_jump &&
          rotation_angle(jump) <= config_.max_jump_angle)
        motion = estimate;
      else
        stats_.bridged = true;
    } else if (!first) {
      stats_.bridged = true;
    }
    if (!first) {
      pose_ = orthonormalized(pose_ * motion);
      if (!stats_.bridged && config_.constant_velocity) velocity_ = motion;
    }
    if (down.size() >= kMinimumFramePoints || !previous_) {
      previous_ = current;
      previous_frame_ = std::move(down);
      previous_pose_ = pose_;
    }
    stats_.total_ms = ms_since(start);
    return pose_;
  }

  const FrameStats& last_stats() const override { return stats_; }
  const PointCloud* last_map_frame(Pose& registration_from_frame) const override {
    registration_from_frame = previous_pose_;
    return &previous_frame_;
  }

 private:
  // The motion from the previous frame to this one (source: this frame, target: the previous).
  Pose align(const Cloud::Ptr& source, const Pose& guess) {
    const Eigen::Matrix4f initial = to_matrix(guess).cast<float>();
    Cloud aligned;
    Eigen::Matrix4f result = initial;
    // What every PCL registration shares; the method-specific settings come first.
    const auto run = [&](pcl::Registration<pcl::PointXYZ, pcl::PointXYZ>& registration) {
      registration.setMaximumIterations(30);
      registration.setInputSource(source);
      registration.setInputTarget(previous_);
      registration.align(aligned, initial);
      converged_ = registration.hasConverged();
      result = registration.getFinalTransformation();
    };
    if (method_ == PclMethod::kIcp) {
      pcl::IterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> icp;
      icp.setMaxCorrespondenceDistance(1.0);
      icp.setTransformationEpsilon(1e-10);
      run(icp);
      stats_.iterations = icp.nr_iterations_;
    } else if (method_ == PclMethod::kGicp) {
      pcl::GeneralizedIterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> gicp;
      gicp.setMaxCorrespondenceDistance(1.0);
      gicp.setCorrespondenceRandomness(20);
      run(gicp);
      stats_.iterations = gicp.nr_iterations_;
    } else {
      pcl::NormalDistributionsTransform<pcl::PointXYZ, pcl::PointXYZ> ndt;
      ndt.setResolution(static_cast<float>(config_.ndt_resolution));
      ndt.setStepSize(0.1);
      ndt.setTransformationEpsilon(0.001);
      run(ndt);
      stats_.iterations = ndt.getFinalNumIteration();
    }
    return from_matrix(result.cast<double>());
  }

  OdometryConfig config_;
  PclMethod method_;
  Preprocessor preprocessor_;  ///< ours: the peers see the frames our pipelines see
  FrameStats stats_;
  Cloud::Ptr previous_;
  PointCloud previous_frame_;
  Pose pose_ = Pose::Identity(), velocity_ = Pose::Identity(), previous_pose_ = Pose::Identity();
  bool converged_ = false;
};

std::unique_ptr<FrameOdometry> make(const OdometryConfig& config, PclMethod method) {
  return std::make_unique<PclOdometry>(config, method);
}

[[maybe_unused]] const bool kRegistered =
    register_odometry_peer("pcl-icp", "PCL IterativeClosestPoint, frame to frame",
                           [](const OdometryConfig& c) { return make(c, PclMethod::kIcp); }) &&
    register_odometry_peer("pcl-ndt", "PCL NormalDistributionsTransform, frame to frame",
                           [](const OdometryConfig& c) { return make(c, PclMethod::kNdt); }) &&
    register_odometry_peer("pcl-gicp", "PCL GeneralizedIterativeClosestPoint, frame to frame",
                           [](const OdometryConfig& c) { return make(c, PclMethod::kGicp); });

}  // namespace
}  // namespace scanmatch
