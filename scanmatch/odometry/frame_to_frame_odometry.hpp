#pragma once
// Any registration method (registration/methods.hpp) as odometry, as in the papers' comparisons:
// each preprocessed frame registered to the previous one from the motion prior, through the frame
// loop CTF-ICP uses (preprocessing, prior, gate, reported poses).

#include "scanmatch/odometry/odometry_pipeline.hpp"
#include "scanmatch/registration/options.hpp"

namespace scanmatch {

class FrameToFrameOdometry final : public OdometryPipeline {
 public:
  /// config.method is a registration method; throws Error otherwise or for invalid parameters.
  explicit FrameToFrameOdometry(const OdometryConfig& config);
  const PointCloud& last_frame() const override { return previous_; }

 private:
  Pose estimate(const PointCloud& frame, const MotionPrior& prior, const Pose& predicted,
                FrameStats& stats) override;
  void update_reference(PointCloud frame, const PointCloud& map_points, const Pose& pose,
                        bool bridged, FrameStats& stats) override;

  RegistrationOptions registration_;
  std::size_t minimum_points_;
  PointCloud previous_;
};

}  // namespace scanmatch
