#pragma once
// NDT (Magnusson's 3D point-to-distribution form): each point scores -d1 exp(-d2/2 x^T C^-1 x)
// against the voxel Gaussians around it; minimised by Gauss-Newton on the score with its exact
// gradient and the Gauss-Newton part of its Hessian (IRLS weights d1 d2 / 2 exp(-d2/2 q)), which
// keeps the Hessian positive definite far from the optimum.

#include <cmath>

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/geometry/gaussian_voxel_map.hpp"
#include "scanmatch/registration/solver.hpp"

namespace scanmatch {

/// Magnusson's constants d1, d2 of the Gaussian fitted to the mixture of a normal and a uniform
/// outlier distribution, for voxel size `resolution` (m) and outlier probability `outlier_ratio`.
inline void ndt_score_constants(double resolution, double outlier_ratio, double& d1, double& d2) {
  const double c1 = 10.0 * (1.0 - outlier_ratio);
  const double c2 = outlier_ratio / (resolution * resolution * resolution);
  const double d3 = -std::log(c2);
  d1 = -std::log(c1 + c2) - d3;
  d2 = -2.0 * std::log((-std::log(c1 * std::exp(-0.5) + c2) - d3) / d1);
}

struct NdtFactor {
  const PointCloud& source;
  const GaussianVoxelMap& target_map;
  int neighbours;
  double d1, d2;  ///< ndt_score_constants for the voxel size and outlier ratio
  std::size_t size() const { return source.size(); }
  bool linearize(const Pose& T, std::size_t i, LinearSystem& system, const RobustKernel&) const {
    const Eigen::Vector3d p = source.points[i].cast<double>(), x = T * p;
    const Eigen::Matrix<double, 3, 6> J = point_jacobian(T, p);
    bool any = false;
    target_map.for_each_neighbour(x, neighbours, [&](const GaussianVoxel& v) {
      const Eigen::Vector3d r = x - v.mean;
      const double q = r.dot(v.regularized_information * r);
      const double e = std::exp(-0.5 * d2 * q);
      if (e < 1e-12) return;
      system.add_weighted<3>(J, r, v.regularized_information, -0.5 * d1 * d2 * e, d1 * e);
      any = true;
    });
    return any;
  }
};

}  // namespace scanmatch
