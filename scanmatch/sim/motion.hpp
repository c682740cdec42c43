#pragma once
// Sensor motion: a densely sampled trajectory (1 kHz) interpolated linearly in translation and
// by slerp in rotation. The interpolated function is the ground truth: frame poses and the pose of
// every ray's instant come from it, so points and poses are exactly consistent.

#include <Eigen/Geometry>
#include <vector>

#include "scanmatch/core/se3.hpp"
#include "scanmatch/io/trajectory.hpp"
#include "scanmatch/sim/scene.hpp"

namespace scanmatch::sim {

class DenseTrajectory {
 public:
  static constexpr double kStep = 0.001;  ///< s between samples

  DenseTrajectory() = default;
  /// Samples `pose_of_time` every kStep over [0, duration].
  template <typename PoseOfTime>
  DenseTrajectory(double duration, PoseOfTime pose_of_time) {
    const std::size_t n = static_cast<std::size_t>(duration / kStep) + 2;
    translations_.reserve(n);
    rotations_.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
      const Pose T = pose_of_time(static_cast<double>(i) * kStep);
      translations_.push_back(T.translation());
      rotations_.emplace_back(T.linear());
    }
  }
  /// Pose at time t (clamped to the sampled span).
  Pose at(double t) const;
  double duration() const { return kStep * static_cast<double>(translations_.size() - 1); }

 private:
  std::vector<Eigen::Vector3d> translations_;
  std::vector<Eigen::Quaterniond> rotations_;
};

/// A path through free space: waypoints in the ground plane, smoothed by a Catmull-Rom spline.
class GroundPath {
 public:
  GroundPath(const std::vector<Eigen::Vector2d>& waypoints, bool closed);
  double length() const { return cumulative_.back(); }
  /// Position at arc length s (wrapped on a closed path, clamped on an open one).
  Eigen::Vector2d position(double s) const;
  /// Heading (rad) at arc length s, from the tangent over +-0.5 m.
  double heading(double s) const;

 private:
  std::vector<Eigen::Vector2d> points_;  // fine polyline, ~5 cm apart
  std::vector<double> cumulative_;
  bool closed_;
};

/// Drives `length` metres along `path` in `duration` seconds (1 s ramps at both ends), the sensor
/// `height` above the ground, pitched and rolled with the ground's slope, plus a small vibration.
DenseTrajectory drive_along(const GroundPath& path, const Ground* ground, double length,
                            double duration, double height, double vibration);
/// A car's speed over time: `start` m/s at the first instant (a recording that begins with the car
/// already moving), then `acceleration` m/s^2 until it reaches `cruise` m/s, which it holds.
struct SpeedProfile {
  double start = 0.0, acceleration = 1.0, cruise = 0.0;
  /// Distance driven after t seconds.
  double distance_at(double t) const;
};
/// Drives along `path` from its start with the speed `speed` for `duration` seconds, on the ground
/// like drive_along (pitch and roll from the slope, the same vibration).
DenseTrajectory cruise_along(const GroundPath& path, const Ground* ground,
                             const SpeedProfile& speed, double duration, double height,
                             double vibration);
/// A hand-held sensor: slow walk along `path` with fast rotations (up to ~250 deg/s in yaw).
DenseTrajectory handheld_along(const GroundPath& path, const Ground* ground, double length,
                               double duration, double height);
/// A hand-held sensor carried at walking pace along `path` while the person looks around: yaw
/// sweeps of up to ~55 deg/s over the path's heading (a recording of a hand-held Livox Avia turns
/// 19 deg/s at the median, 55 at the 95th percentile, walking 0.6 m/s), small roll and pitch.
DenseTrajectory walk_along(const GroundPath& path, const Ground* ground, double length,
                           double duration, double height);
/// Replays a recorded trajectory (interpolated in SE(3)), placed at `start` in the scene; poses
/// without timestamps are taken at `rate_hz`.
DenseTrajectory replay(const Trajectory& recorded, const Pose& start, double rate_hz);

}  // namespace scanmatch::sim
