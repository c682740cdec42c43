#pragma once
// LOAM's planar factor (docs/methods.md section 3): the target's planar features searched with a
// k-d tree.

#include <cstdlib>

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/geometry/kdtree.hpp"
#include "scanmatch/registration/factors/loam_edge.hpp"
#include "scanmatch/registration/solver.hpp"

namespace scanmatch {

// Planar point p: nearest planar q, a second point m on q's ring and a third r on an adjacent
// ring; the residual is the signed distance to the plane through q, m, r.
struct LoamPlaneFactor {
  const PointCloud& source;
  const PointCloud& target;
  const KdTree& tree;
  double max_distance;
  std::size_t size() const { return source.size(); }
  bool linearize(const Pose& T, std::size_t i, LinearSystem& system,
                 const RobustKernel& kernel) const {
    const Eigen::Vector3d p = source.points[i].cast<double>(), x = T * p;
    LoamCandidates near;
    if (!near.search(tree, x, max_distance, 3)) return false;
    const std::size_t* idx = near.index;
    const std::size_t found = near.count;
    const int ring_q = target.ring[idx[0]];
    std::size_t m = LoamCandidates::kMax, r = LoamCandidates::kMax;
    for (std::size_t k = 1; k < found; ++k) {
      const int ring = target.ring[idx[k]];
      if (m == LoamCandidates::kMax && ring == ring_q) m = k;
      if (r == LoamCandidates::kMax && std::abs(ring - ring_q) == 1) r = k;
    }
    // Fall back to the nearest other points where the rings do not offer both.
    if (m == LoamCandidates::kMax) m = (r == 1) ? 2 : 1;
    if (r == LoamCandidates::kMax) r = (m == 1) ? 2 : 1;
    const Eigen::Vector3d q = target.points[idx[0]].cast<double>();
    const Eigen::Vector3d n =
        (q - target.points[idx[r]].cast<double>()).cross(q - target.points[idx[m]].cast<double>());
    if (n.squaredNorm() < 1e-10) return false;
    const Eigen::Vector3d normal = n.normalized();
    const Eigen::Matrix<double, 1, 1> residual(normal.dot(x - q));
    system.add<1>(normal.transpose() * point_jacobian(T, p), residual,
                  Eigen::Matrix<double, 1, 1>::Identity(), kernel);
    return true;
  }
};

}  // namespace scanmatch
