#pragma once
// GICP (Segal et al.): r = T p - q, information (C_q + R C_p R^T)^-1 with plane-regularised
// covariances of both points.

#include <vector>

#include "scanmatch/registration/factors/correspondence.hpp"
#include "scanmatch/registration/solver.hpp"

namespace scanmatch {

struct GicpFactor : NearestTargetSearch {
  const std::vector<Eigen::Matrix3d>& source_covariances;
  const std::vector<Eigen::Matrix3d>& target_covariances;
  bool linearize(const Pose& T, std::size_t i, LinearSystem& system,
                 const RobustKernel& kernel) const {
    NearestTargets<1> near;
    if (!search(T, i, near)) return false;
    const std::size_t j = near.index[0];
    const Eigen::Matrix3d& R = T.linear();
    const Eigen::Matrix3d C = target_covariances[j] + R * source_covariances[i] * R.transpose();
    system.add<3>(point_jacobian(T, near.p), near.x - target.points[j].cast<double>(), C.inverse(),
                  kernel);
    return true;
  }
};

}  // namespace scanmatch
