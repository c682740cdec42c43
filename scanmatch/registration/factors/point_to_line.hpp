#pragma once
// Point-to-line (Censi's PL-ICP in 3D): the distance from T p to the line through the two nearest
// target points. add_point_to_line is shared with LOAM's edge factor.

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/geometry/kdtree.hpp"
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

}  // namespace scanmatch
