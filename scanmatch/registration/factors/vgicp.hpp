#pragma once
// VGICP (Koide et al.): the source point's distribution against the target voxel Gaussians
// around T p (1, 7 or 27 voxels), information (C_voxel + R C_p R^T)^-1.

#include <vector>

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/geometry/gaussian_voxel_map.hpp"
#include "scanmatch/registration/solver.hpp"

namespace scanmatch {

struct VgicpFactor {
  const PointCloud& source;
  const std::vector<Eigen::Matrix3d>& source_covariances;
  const GaussianVoxelMap& target_map;
  int neighbours;
  std::size_t size() const { return source.size(); }
  bool linearize(const Pose& T, std::size_t i, LinearSystem& system,
                 const RobustKernel& kernel) const {
    const Eigen::Vector3d p = source.points[i].cast<double>(), x = T * p;
    const Eigen::Matrix<double, 3, 6> J = point_jacobian(T, p);
    const Eigen::Matrix3d RCR = T.linear() * source_covariances[i] * T.linear().transpose();
    bool any = false;
    target_map.for_each_neighbour(x, neighbours, [&](const GaussianVoxel& v) {
      system.add<3>(J, x - v.mean, (v.regularized_covariance + RCR).inverse(), kernel);
      any = true;
    });
    return any;
  }
};

}  // namespace scanmatch
