#pragma once
// GICP (Segal et al.): r = T p - q, information (C_q + R C_p R^T)^-1 with plane-regularised
// covariances of both points.

#include <vector>

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/geometry/kdtree.hpp"
#include "scanmatch/registration/solver.hpp"

namespace scanmatch {

struct GicpFactor {
  const PointCloud& source;
  const PointCloud& target;
  const KdTree& tree;
  const std::vector<Eigen::Matrix3d>& source_covariances;
  const std::vector<Eigen::Matrix3d>& target_covariances;
  double max_distance;
  std::size_t size() const { return source.size(); }
  bool linearize(const Pose& T, std::size_t i, LinearSystem& system,
                 const RobustKernel& kernel) const {
    const Eigen::Vector3d p = source.points[i].cast<double>(), x = T * p;
    std::size_t j;
    float d2;
    if (!tree.nearest(x.cast<float>(), static_cast<float>(max_distance * max_distance), j, d2))
      return false;
    const Eigen::Matrix3d& R = T.linear();
    const Eigen::Matrix3d C = target_covariances[j] + R * source_covariances[i] * R.transpose();
    system.add<3>(point_jacobian(T, p), x - target.points[j].cast<double>(), C.inverse(), kernel);
    return true;
  }
};

}  // namespace scanmatch
