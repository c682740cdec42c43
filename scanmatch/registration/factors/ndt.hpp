#pragma once
// NDT (Magnusson's 3D point-to-distribution form): each point scores -d1 exp(-d2/2 x^T C^-1 x)
// against the voxel Gaussians around it; minimised by Gauss-Newton on the score with its exact
// gradient and the Gauss-Newton part of its Hessian (IRLS weights d1 d2 / 2 exp(-d2/2 q)), which
// keeps the Hessian positive definite far from the optimum.

#include <cmath>
#include <vector>

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
  /// As CtfFineFactor::hints: one per source point when neighbours = 1, or empty.
  mutable std::vector<VoxelHint> hints = {};
  std::size_t size() const { return source.size(); }
  /// Sensor-centred (SensorCentredSystem): for J = [-[y]x, I] and information W,
  /// J^T W J = [[-M [y]x, M], [M^T, W]] with M = [y]x W, and J^T W r = [y x W r; W r].
  void linearize_range(const Pose& T, std::size_t begin, std::size_t end, LinearSystem& system,
                       const RobustKernel&) const {
    const Eigen::Matrix3d& R = T.linear();
    const Eigen::Vector3d t = T.translation();
    SensorCentredSystem centred;
    Eigen::Matrix3d rotation_block = Eigen::Matrix3d::Zero(), cross_block = rotation_block,
                    translation_block = rotation_block;
    const GaussianVoxel* found[27];
    for (std::size_t i = begin; i < end; ++i) {
      const Eigen::Vector3d y = R * source.points[i].cast<double>(), x = y + t;
      const int count =
          target_map.gather_neighbours(x, neighbours, found, hints.empty() ? nullptr : &hints[i]);
      for (int k = 0; k < count; ++k) {
        const GaussianVoxel& v = *found[k];
        const Eigen::Vector3d r = x - v.mean;
        const Eigen::Matrix3d& W = v.regularized_information;
        const Eigen::Vector3d Wr = W * r;
        const double q = r.dot(Wr);
        const double e = std::exp(-0.5 * d2 * q);
        if (e < 1e-12) continue;
        const double weight = -0.5 * d1 * d2 * e;  // IRLS weight of the score (d1 < 0)
        Eigen::Matrix3d M, MyT;                    // M = [y]x W: column j is y x W_j
        for (int j = 0; j < 3; ++j) M.col(j) = y.cross(W.col(j));
        // -M [y]x: row i is y x M_i (as a row), since m^T [y]x = (m x y)^T.
        for (int j = 0; j < 3; ++j) MyT.row(j) = y.cross(M.row(j).transpose()).transpose();
        rotation_block.noalias() += weight * MyT;
        cross_block.noalias() += weight * M;
        translation_block.noalias() += weight * W;
        const Eigen::Vector3d u = weight * Wr;
        centred.b.head<3>() += y.cross(u);
        centred.b.tail<3>() += u;
        centred.cost += d1 * e;
        centred.squared_error += r.squaredNorm();
        ++centred.inliers;
      }
    }
    centred.H.topLeftCorner<3, 3>() = rotation_block;
    centred.H.topRightCorner<3, 3>() = cross_block;
    centred.H.bottomLeftCorner<3, 3>() = cross_block.transpose();
    centred.H.bottomRightCorner<3, 3>() = translation_block;
    centred.add_to(system, R);
  }
};

/// NDT of `source` against `grid` (the target's Gaussians), with the score constants of the
/// grid's voxel size and `outlier_ratio`.
inline NdtFactor ndt_factor(const PointCloud& source, const GaussianVoxelMap& grid, int neighbours,
                            double outlier_ratio) {
  double d1 = 0.0, d2 = 0.0;
  ndt_score_constants(grid.options().voxel_size, outlier_ratio, d1, d2);
  return NdtFactor{source, grid, neighbours, d1, d2};
}

}  // namespace scanmatch
