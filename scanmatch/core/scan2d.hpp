#pragma once
// 2D poses and laser scans as the 2D methods, mapping and evaluation use them: poses are
// Eigen::Isometry2d (x, y, theta); scans are points in the laser frame, in beam order.

#include <Eigen/Geometry>
#include <cstddef>
#include <vector>

#include "scanmatch/core/se3.hpp"

namespace scanmatch {

using Pose2 = Eigen::Isometry2d;
Pose2 pose2(double x, double y, double theta);
Pose2 pose2(const Eigen::Vector3d& xytheta);  ///< from (x, y, theta), as CARMEN logs store poses
double pose2_angle(const Pose2& T);           ///< theta in (-pi, pi]
/// x, y and heading (the angle of the x axis about z) of a 3D pose.
Pose2 planar_pose(const Pose& T);

struct Scan2D {
  std::vector<Eigen::Vector2d> points;  ///< valid returns, in beam order, laser frame, m
  /// End points of no-return beams at the maximum range (free space for grid maps), laser frame.
  std::vector<Eigen::Vector2d> misses;
  bool circular = false;  ///< a 360-degree scan: the last beam neighbours the first
  /// Per point, when its beam was measured, s after the first beam (empty: not known). A
  /// spinning laser sweeps while it moves; Mapper2D deskews with these.
  std::vector<double> times;
};

/// Index of the beam-order neighbour of point j (`step` -1 or +1) among `count` points, wrapping
/// on a circular scan; -1 past the ends of an open one.
inline long beam_neighbour(long count, bool circular, long j, long step) {
  long k = j + step;
  if (circular) k = (k + count) % count;
  return k < 0 || k >= count ? -1 : k;
}
inline long beam_neighbour(const Scan2D& scan, std::size_t j, long step) {
  return beam_neighbour(static_cast<long>(scan.points.size()), scan.circular, static_cast<long>(j),
                        step);
}

}  // namespace scanmatch
