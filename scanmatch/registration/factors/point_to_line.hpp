#pragma once
// Point-to-line (Censi's PL-ICP in 3D): the distance from T p to the line through the two nearest
// target points. add_point_to_line is shared with LOAM's edge factor.

#include "scanmatch/registration/factors/correspondence.hpp"
#include "scanmatch/registration/solver.hpp"

namespace scanmatch {

/// Adds the distance from T p to the line through q with direction d as the 3-vector
/// (I - d d^T / |d|^2)(T p - q); false for a degenerate line.
inline bool add_point_to_line(const Pose& T, const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                              const Eigen::Vector3d& d, LinearSystem& system,
                              const RobustKernel& kernel) {
  if (d.squaredNorm() < 1e-10) return false;
  const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - d * d.transpose() / d.squaredNorm();
  system.add<3>(P * point_jacobian(T, p), P * (T * p - q), Eigen::Matrix3d::Identity(), kernel);
  return true;
}

struct PointToLineFactor : NearestTargetSearch {
  bool linearize(const Pose& T, std::size_t i, LinearSystem& system,
                 const RobustKernel& kernel) const {
    NearestTargets<2> near;
    if (!search(T, i, near)) return false;
    const Eigen::Vector3d q1 = target.points[near.index[0]].cast<double>();
    return add_point_to_line(T, near.p, q1, target.points[near.index[1]].cast<double>() - q1,
                             system, kernel);
  }
};

}  // namespace scanmatch
