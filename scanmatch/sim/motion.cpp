#include "scanmatch/sim/motion.hpp"

#include <algorithm>
#include <cmath>

#include "scanmatch/core/error.hpp"

namespace scanmatch::sim {

Pose DenseTrajectory::at(double t) const {
  const double x = std::clamp(t / kStep, 0.0, static_cast<double>(translations_.size() - 1));
  const std::size_t i = std::min(static_cast<std::size_t>(x), translations_.size() - 2);
  const double f = x - static_cast<double>(i);
  Pose T = Pose::Identity();
  T.translation() = (1.0 - f) * translations_[i] + f * translations_[i + 1];
  T.linear() = rotations_[i].slerp(f, rotations_[i + 1]).toRotationMatrix();
  return T;
}

GroundPath::GroundPath(const std::vector<Eigen::Vector2d>& w, bool closed) : closed_(closed) {
  if (w.size() < 2) throw Error("simulator: a path needs at least two waypoints");
  const std::size_t n = w.size();
  const auto at = [&](long i) {
    if (closed)
      return w[static_cast<std::size_t>((i % static_cast<long>(n) + static_cast<long>(n)) %
                                        static_cast<long>(n))];
    return w[static_cast<std::size_t>(std::clamp<long>(i, 0, static_cast<long>(n) - 1))];
  };
  const long segments = closed ? static_cast<long>(n) : static_cast<long>(n) - 1;
  for (long s = 0; s < segments; ++s) {
    const Eigen::Vector2d p0 = at(s - 1), p1 = at(s), p2 = at(s + 1), p3 = at(s + 2);
    const int steps = std::max(4, static_cast<int>((p2 - p1).norm() / 0.05));
    for (int k = 0; k < steps; ++k) {
      const double u = static_cast<double>(k) / steps, u2 = u * u, u3 = u2 * u;
      points_.push_back(0.5 * ((2 * p1) + (-p0 + p2) * u + (2 * p0 - 5 * p1 + 4 * p2 - p3) * u2 +
                               (-p0 + 3 * p1 - 3 * p2 + p3) * u3));
    }
  }
  points_.push_back(closed ? points_.front() : w.back());
  cumulative_.assign(points_.size(), 0.0);
  for (std::size_t i = 1; i < points_.size(); ++i)
    cumulative_[i] = cumulative_[i - 1] + (points_[i] - points_[i - 1]).norm();
}

Eigen::Vector2d GroundPath::position(double s) const {
  const double total = length();
  s = closed_ ? s - std::floor(s / total) * total : std::clamp(s, 0.0, total);
  const auto it = std::upper_bound(cumulative_.begin(), cumulative_.end(), s);
  const std::size_t i = std::clamp<std::size_t>(static_cast<std::size_t>(it - cumulative_.begin()),
                                                1, points_.size() - 1);
  const double span = cumulative_[i] - cumulative_[i - 1];
  const double f = span > 0 ? (s - cumulative_[i - 1]) / span : 0.0;
  return (1.0 - f) * points_[i - 1] + f * points_[i];
}

double GroundPath::heading(double s) const {
  const Eigen::Vector2d d = position(s + 0.5) - position(s - 0.5);
  return std::atan2(d.y(), d.x());
}

namespace {
// Distance along the path after t seconds: 1 s linear ramps at both ends, cruise in between.
double distance_at(double t, double length, double duration) {
  const double ramp = std::min(1.0, duration / 4);
  const double cruise = length / (duration - ramp);
  t = std::clamp(t, 0.0, duration);
  if (t < ramp) return 0.5 * cruise * t * t / ramp;
  if (t > duration - ramp) {
    const double r = duration - t;
    return length - 0.5 * cruise * r * r / ramp;
  }
  return 0.5 * cruise * ramp + cruise * (t - ramp);
}

Pose pose_on_ground(const Eigen::Vector2d& xy, double yaw, const Ground* ground, double height,
                    double extra_roll, double extra_pitch) {
  double z = height, roll = 0, pitch = 0;
  if (ground) {
    z += ground->height(xy.x(), xy.y());
    const Eigen::Vector3d n = ground->normal(xy.x(), xy.y());
    // Slope along and across the heading gives pitch and roll.
    const Eigen::Vector2d forward(std::cos(yaw), std::sin(yaw)),
        left(-std::sin(yaw), std::cos(yaw));
    pitch = std::atan2(-n.head<2>().dot(forward), n.z());
    roll = std::atan2(n.head<2>().dot(left), n.z());
  }
  return from_xyz_rpy(xy.x(), xy.y(), z, roll + extra_roll, pitch + extra_pitch, yaw);
}
}  // namespace

DenseTrajectory drive_along(const GroundPath& path, const Ground* ground, double length,
                            double duration, double height, double vibration) {
  return DenseTrajectory(duration, [&](double t) {
    const double s = distance_at(t, length, duration);
    const double wobble_roll = vibration * std::sin(2 * M_PI * 3.1 * t);
    const double wobble_pitch = vibration * std::sin(2 * M_PI * 2.3 * t + 1.0);
    return pose_on_ground(path.position(s), path.heading(s), ground, height, wobble_roll,
                          wobble_pitch);
  });
}

double SpeedProfile::distance_at(double t) const {
  const double ramp = std::max(0.0, (cruise - start) / acceleration);
  if (t < ramp) return start * t + 0.5 * acceleration * t * t;
  return start * ramp + 0.5 * acceleration * ramp * ramp + cruise * (t - ramp);
}

DenseTrajectory cruise_along(const GroundPath& path, const Ground* ground,
                             const SpeedProfile& speed, double duration, double height,
                             double vibration) {
  return DenseTrajectory(duration, [&](double t) {
    const double s = speed.distance_at(t);
    const double wobble_roll = vibration * std::sin(2 * M_PI * 3.1 * t);
    const double wobble_pitch = vibration * std::sin(2 * M_PI * 2.3 * t + 1.0);
    return pose_on_ground(path.position(s), path.heading(s), ground, height, wobble_roll,
                          wobble_pitch);
  });
}

DenseTrajectory handheld_along(const GroundPath& path, const Ground* ground, double length,
                               double duration, double height) {
  return DenseTrajectory(duration, [&](double t) {
    const double s = distance_at(t, length, duration);
    // Sums of sines: peak yaw rate 0.8 * 2 pi * 0.45 + 0.3 * 2 pi * 1.3 ~ 4.7 rad/s.
    const double yaw =
        path.heading(s) + 0.8 * std::sin(2 * M_PI * 0.45 * t) + 0.3 * std::sin(2 * M_PI * 1.3 * t);
    const double roll = 0.15 * std::sin(2 * M_PI * 0.7 * t + 0.5);
    const double pitch = 0.2 * std::sin(2 * M_PI * 0.9 * t + 1.7);
    Pose T = pose_on_ground(path.position(s), yaw, ground, height, roll, pitch);
    T.translation().z() += 0.05 * std::sin(2 * M_PI * 1.8 * t);  // gait bounce
    return T;
  });
}

DenseTrajectory walk_along(const GroundPath& path, const Ground* ground, double length,
                           double duration, double height) {
  return DenseTrajectory(duration, [&](double t) {
    const double s = distance_at(t, length, duration);
    // Peak yaw rate 0.6 * 2 pi * 0.12 + 0.25 * 2 pi * 0.35 ~ 1.0 rad/s (57 deg/s).
    const double yaw = path.heading(s) + 0.6 * std::sin(2 * M_PI * 0.12 * t) +
                       0.25 * std::sin(2 * M_PI * 0.35 * t + 0.8);
    const double roll = 0.04 * std::sin(2 * M_PI * 0.3 * t + 0.5);
    const double pitch = 0.06 * std::sin(2 * M_PI * 0.25 * t + 1.7);
    Pose T = pose_on_ground(path.position(s), yaw, ground, height, roll, pitch);
    T.translation().z() += 0.01 * std::sin(2 * M_PI * 1.8 * t);  // gait bounce
    return T;
  });
}

DenseTrajectory replay(const Trajectory& recorded, const Pose& start, double rate_hz) {
  if (recorded.size() < 2) throw Error("simulator: a replayed trajectory needs at least two poses");
  std::vector<double> times = recorded.timestamps;
  if (times.empty())
    for (std::size_t i = 0; i < recorded.size(); ++i)
      times.push_back(static_cast<double>(i) / rate_hz);
  const double t0 = times.front();
  for (std::size_t i = 1; i < times.size(); ++i)
    if (!(times[i] > times[i - 1]))
      throw Error("simulator: replayed trajectory timestamps must increase");
  const Pose first_inverse = recorded.poses.front().inverse();
  return DenseTrajectory(times.back() - t0, [&](double t) {
    const auto it = std::upper_bound(times.begin(), times.end(), t + t0);
    const std::size_t i =
        std::clamp<std::size_t>(static_cast<std::size_t>(it - times.begin()), 1, times.size() - 1);
    const double f = std::clamp((t + t0 - times[i - 1]) / (times[i] - times[i - 1]), 0.0, 1.0);
    return start * first_inverse * interpolate(recorded.poses[i - 1], recorded.poses[i], f);
  });
}

}  // namespace scanmatch::sim
