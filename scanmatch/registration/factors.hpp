#pragma once
// The per-point factors of the registration methods: each finds a correspondence for source point
// i under the current pose and adds its residual and Jacobian (see solver.hpp). One struct per
// method; the target-side structures (k-d tree, normals, covariances, voxel map) are built once by
// the caller and only referenced here.

#include <cmath>
#include <vector>

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/geometry/gaussian_voxel_map.hpp"
#include "scanmatch/geometry/kdtree.hpp"
#include "scanmatch/registration/solver.hpp"

namespace scanmatch {

/// Adds the distance from T p to the line through q with direction d as the 3-vector
/// (I - d d^T / |d|^2)(T p - q); false for a degenerate line. Shared by point-to-line and LOAM
/// edges.
inline bool add_point_to_line(const Pose& T, const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                              const Eigen::Vector3d& d, LinearSystem& system,
                              const RobustKernel& kernel) {
  if (d.squaredNorm() < 1e-10) return false;
  const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - d * d.transpose() / d.squaredNorm();
  system.add<3>(P * point_jacobian(T, p), P * (T * p - q), Eigen::Matrix3d::Identity(), kernel);
  return true;
}

/// Point-to-point: r = T p - q, q the nearest target point (k-d tree, or exhaustive search).
struct PointToPointFactor {
  const PointCloud& source;
  const PointCloud& target;
  const KdTree* tree;  ///< nullptr: brute-force nearest neighbour
  double max_distance;
  std::size_t size() const { return source.size(); }
  bool nearest(const Eigen::Vector3d& x, std::size_t& index) const;
  bool linearize(const Pose& T, std::size_t i, LinearSystem& system,
                 const RobustKernel& kernel) const {
    const Eigen::Vector3d p = source.points[i].cast<double>(), x = T * p;
    std::size_t j;
    if (!nearest(x, j)) return false;
    const Eigen::Vector3d r = x - target.points[j].cast<double>();
    system.add<3>(point_jacobian(T, p), r, Eigen::Matrix3d::Identity(), kernel);
    return true;
  }
};

/// Point-to-plane: r = n . (T p - q) with the target normal n at the nearest point q.
struct PointToPlaneFactor {
  const PointCloud& source;
  const PointCloud& target;
  const KdTree& tree;
  const std::vector<Eigen::Vector3d>& target_normals;
  double max_distance;
  std::size_t size() const { return source.size(); }
  bool linearize(const Pose& T, std::size_t i, LinearSystem& system,
                 const RobustKernel& kernel) const {
    const Eigen::Vector3d p = source.points[i].cast<double>(), x = T * p;
    std::size_t j;
    float d2;
    if (!tree.nearest(x.cast<float>(), static_cast<float>(max_distance * max_distance), j, d2))
      return false;
    const Eigen::Vector3d& n = target_normals[j];
    const Eigen::Matrix<double, 1, 1> r(n.dot(x - target.points[j].cast<double>()));
    system.add<1>(n.transpose() * point_jacobian(T, p), r, Eigen::Matrix<double, 1, 1>::Identity(),
                  kernel);
    return true;
  }
};

/// Point-to-line (Censi's PL-ICP in 3D): distance from T p to the line through the two nearest
/// target points, as the 3-vector (I - d d^T)(T p - q1).
struct PointToLineFactor {
  const PointCloud& source;
  const PointCloud& target;
  const KdTree& tree;
  double max_distance;
  std::size_t size() const { return source.size(); }
  bool linearize(const Pose& T, std::size_t i, LinearSystem& system,
                 const RobustKernel& kernel) const {
    const Eigen::Vector3d p = source.points[i].cast<double>(), x = T * p;
    std::size_t idx[2];
    float d2[2];
    if (tree.knn(x.cast<float>(), 2, idx, d2) < 2 || d2[0] > max_distance * max_distance)
      return false;
    const Eigen::Vector3d q1 = target.points[idx[0]].cast<double>();
    return add_point_to_line(T, p, q1, target.points[idx[1]].cast<double>() - q1, system, kernel);
  }
};

/// GICP (Segal et al.): r = T p - q, information (C_q + R C_p R^T)^-1 with plane-regularised
/// covariances of both points.
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

/// VGICP (Koide et al.): source point distribution against the target voxel Gaussians around T p
/// (1, 7 or 27 voxels), information (C_voxel + R C_p R^T)^-1.
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

/// NDT (Magnusson's 3D point-to-distribution form): each point scores
/// -d1 exp(-d2/2 x^T C^-1 x) against the voxel Gaussians around it; minimised by Gauss-Newton on
/// the score with its exact gradient and the Gauss-Newton part of its Hessian (IRLS weights
/// d1 d2 / 2 exp(-d2/2 q)), which keeps the Hessian positive definite far from the optimum.
struct NdtFactor {
  const PointCloud& source;
  const GaussianVoxelMap& target_map;
  int neighbours;
  double d1, d2;  ///< Magnusson's Gaussian-fit constants for the voxel size and outlier ratio
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

/// CTF-ICP fine stage (METHODS.md section 1 step 3): r = T p - mu of the map voxel containing
/// T p, information Q diag(1/eps, 1, 1) Q^T (covariance eigenvalues normalised to (1, 1, eps)).
/// That information is exactly I + (1/eps - 1) n n^T with n the voxel normal, which lets the
/// normal equations be formed from a 6-vector instead of 6x3 products (the hot loop of the
/// odometry).
struct CtfFineFactor {
  const PointCloud& source;
  const GaussianVoxelMap& map;
  int neighbours;
  /// Voxels whose flatness (smallest / middle eigenvalue) exceeds this are not planes (corners,
  /// foliage) and are skipped; 1 keeps every voxel, as the paper does.
  float max_flatness = 1.0f;
  std::size_t size() const { return source.size(); }
  bool linearize(const Pose& T, std::size_t i, LinearSystem& system,
                 const RobustKernel& kernel) const {
    const Eigen::Vector3d p = source.points[i].cast<double>(), x = T * p;
    const double stiffness = 1.0 / map.options().planar_epsilon - 1.0;
    const Eigen::Matrix3d& R = T.linear();
    bool any = false;
    map.for_each_neighbour(x, neighbours, [&](const GaussianVoxel& v) {
      if (v.flatness > max_flatness) return;
      const Eigen::Vector3d r = x - v.mean;
      const double along_normal = v.normal.dot(r);
      const double s = r.squaredNorm() + stiffness * along_normal * along_normal;
      const double w = kernel.weight(s);
      // J^T u = [p x (R^T u); R^T u] for J = [-R [p]x, R].
      const Eigen::Vector3d Rn = R.transpose() * v.normal, Rr = R.transpose() * r;
      Vector6d g, Jr;
      g << p.cross(Rn), Rn;
      Jr << p.cross(Rr), Rr;
      // J^T J = [[|p|^2 I - p p^T, [p]x], [-[p]x, I]].
      Matrix6d JtJ;
      const Eigen::Matrix3d px = skew(p);
      JtJ.topLeftCorner<3, 3>() = p.squaredNorm() * Eigen::Matrix3d::Identity() - p * p.transpose();
      JtJ.topRightCorner<3, 3>() = px;
      JtJ.bottomLeftCorner<3, 3>() = -px;
      JtJ.bottomRightCorner<3, 3>().setIdentity();
      system.H.noalias() += w * (JtJ + stiffness * g * g.transpose());
      system.b.noalias() += w * (Jr + stiffness * along_normal * g);
      system.cost += kernel.cost(s);
      system.squared_error += r.squaredNorm();
      ++system.inliers;
      any = true;
    });
    return any;
  }
};

}  // namespace scanmatch
