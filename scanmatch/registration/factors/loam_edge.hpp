#pragma once
// LOAM's edge factor (METHODS.md section 3): the target's edge features searched with a k-d tree.

#include <cstdlib>

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/geometry/kdtree.hpp"
#include "scanmatch/registration/factors/point_to_line.hpp"
#include "scanmatch/registration/solver.hpp"

namespace scanmatch {

/// k-nearest candidates the LOAM factors search for neighbours on the right rings.
inline constexpr std::size_t kLoamCandidates = 8;

// Edge point p: nearest target edge q and a neighbour r of q on an adjacent ring; the residual is
// the component of T p - q orthogonal to the line qr (its norm is |(p - q) x (p - r)| / |q - r|).
struct LoamEdgeFactor {
  const PointCloud& source;
  const PointCloud& target;
  const KdTree& tree;
  double max_distance;
  std::size_t size() const { return source.size(); }
  bool linearize(const Pose& T, std::size_t i, LinearSystem& system,
                 const RobustKernel& kernel) const {
    const Eigen::Vector3d p = source.points[i].cast<double>(), x = T * p;
    std::size_t idx[kLoamCandidates];
    float d2[kLoamCandidates];
    const std::size_t found = tree.knn(x.cast<float>(), kLoamCandidates, idx, d2);
    if (found < 2 || d2[0] > max_distance * max_distance) return false;
    const int ring_q = target.ring[idx[0]];
    std::size_t r = idx[1];
    for (std::size_t k = 1; k < found; ++k)
      if (std::abs(static_cast<int>(target.ring[idx[k]]) - ring_q) == 1) {
        r = idx[k];
        break;
      }
    const Eigen::Vector3d q = target.points[idx[0]].cast<double>();
    return add_point_to_line(T, p, q, target.points[r].cast<double>() - q, system, kernel);
  }
};

}  // namespace scanmatch
