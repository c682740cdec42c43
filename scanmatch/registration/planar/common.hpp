#pragma once
// Small helpers the 2D methods share (registration/planar/ only).

#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "scanmatch/core/scan2d.hpp"

namespace scanmatch::planar {

inline std::vector<Eigen::Vector2d> transformed(const std::vector<Eigen::Vector2d>& points,
                                                const Pose2& T) {
  std::vector<Eigen::Vector2d> out(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) out[i] = T * points[i];
  return out;
}

inline Eigen::Vector2d centroid(const std::vector<Eigen::Vector2d>& points) {
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& p : points) c += p;
  return points.empty() ? c : Eigen::Vector2d(c / static_cast<double>(points.size()));
}

/// A step below `tolerance` in translation (m) and rotation (rad): converged.
inline bool small_step(const Pose2& step, double tolerance) {
  return step.translation().norm() < tolerance && std::abs(pose2_angle(step)) < tolerance;
}

}  // namespace scanmatch::planar
