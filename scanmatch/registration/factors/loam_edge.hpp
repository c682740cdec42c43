#pragma once
// LOAM's edge factor (docs/methods.md section 3): the target's edge features searched with a k-d
// tree.

#include <cstdlib>

#include "scanmatch/registration/factors/correspondence.hpp"
#include "scanmatch/registration/factors/point_to_line.hpp"
#include "scanmatch/registration/solver.hpp"

namespace scanmatch {

/// The nearest target features of a point, closest first: where the LOAM factors look for
/// neighbours on the right rings.
inline constexpr std::size_t kLoamCandidates = 8;

// Edge point p: nearest target edge q and a neighbour r of q on an adjacent ring; the residual is
// the component of T p - q orthogonal to the line qr (its norm is |(p - q) x (p - r)| / |q - r|).
struct LoamEdgeFactor : NearestTargetSearch {
  bool linearize(const Pose& T, std::size_t i, LinearSystem& system,
                 const RobustKernel& kernel) const {
    NearestTargets<kLoamCandidates> near;
    if (!search(T, i, near, 2)) return false;
    const auto& idx = near.index;
    const int ring_q = target.ring[idx[0]];
    std::size_t r = idx[1];
    for (std::size_t k = 1; k < near.count; ++k)
      if (std::abs(static_cast<int>(target.ring[idx[k]]) - ring_q) == 1) {
        r = idx[k];
        break;
      }
    const Eigen::Vector3d q = target.points[idx[0]].cast<double>();
    return add_point_to_line(T, near.p, q, target.points[r].cast<double>() - q, system, kernel);
  }
};

}  // namespace scanmatch
