#pragma once
// LOAM's planar factor (docs/methods.md section 3): the target's planar features searched with a
// k-d tree.

#include <cstdlib>

#include "scanmatch/registration/factors/correspondence.hpp"
#include "scanmatch/registration/factors/loam_edge.hpp"
#include "scanmatch/registration/solver.hpp"

namespace scanmatch {

// Planar point p: nearest planar q, a second point m on q's ring and a third r on an adjacent
// ring; the residual is the signed distance to the plane through q, m, r.
struct LoamPlaneFactor : NearestTargetSearch {
  bool linearize(const Pose& T, std::size_t i, LinearSystem& system,
                 const RobustKernel& kernel) const {
    NearestTargets<kLoamCandidates> near;
    if (!search(T, i, near, 3)) return false;
    const auto& idx = near.index;
    const int ring_q = target.ring[idx[0]];
    constexpr std::size_t kNone = kLoamCandidates;
    std::size_t m = kNone, r = kNone;
    for (std::size_t k = 1; k < near.count; ++k) {
      const int ring = target.ring[idx[k]];
      if (m == kNone && ring == ring_q) m = k;
      if (r == kNone && std::abs(ring - ring_q) == 1) r = k;
    }
    // Fall back to the nearest other points where the rings do not offer both.
    if (m == kNone) m = (r == 1) ? 2 : 1;
    if (r == kNone) r = (m == 1) ? 2 : 1;
    const Eigen::Vector3d q = target.points[idx[0]].cast<double>();
    const Eigen::Vector3d n =
        (q - target.points[idx[r]].cast<double>()).cross(q - target.points[idx[m]].cast<double>());
    if (n.squaredNorm() < 1e-10) return false;
    const Eigen::Vector3d normal = n.normalized();
    const Eigen::Matrix<double, 1, 1> residual(normal.dot(near.x - q));
    system.add<1>(normal.transpose() * point_jacobian(T, near.p), residual,
                  Eigen::Matrix<double, 1, 1>::Identity(), kernel);
    return true;
  }
};

}  // namespace scanmatch
