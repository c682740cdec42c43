#pragma once
// Point-to-plane: r = n . (T p - q) with the target normal n at the nearest point q.

#include <vector>

#include "scanmatch/registration/factors/correspondence.hpp"
#include "scanmatch/registration/solver.hpp"

namespace scanmatch {

struct PointToPlaneFactor : NearestTargetSearch {
  const std::vector<Eigen::Vector3d>& target_normals;
  bool linearize(const Pose& T, std::size_t i, LinearSystem& system,
                 const RobustKernel& kernel) const {
    NearestTargets<1> near;
    if (!search(T, i, near)) return false;
    const std::size_t j = near.index[0];
    const Eigen::Vector3d& n = target_normals[j];
    const Eigen::Matrix<double, 1, 1> r(n.dot(near.x - target.points[j].cast<double>()));
    system.add<1>(n.transpose() * point_jacobian(T, near.p), r,
                  Eigen::Matrix<double, 1, 1>::Identity(), kernel);
    return true;
  }
};

}  // namespace scanmatch
