#pragma once
// Point-to-plane: r = n . (T p - q) with the target normal n at the nearest point q.

#include <vector>

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/geometry/kdtree.hpp"
#include "scanmatch/registration/solver.hpp"

namespace scanmatch {

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

}  // namespace scanmatch
