#pragma once
// LOAM's edge factor (docs/methods.md section 3): the target's edge features searched with a k-d
// tree.

#include <cstdlib>

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/geometry/kdtree.hpp"
#include "scanmatch/registration/factors/point_to_line.hpp"
#include "scanmatch/registration/solver.hpp"

namespace scanmatch {

/// The nearest target features of a point, closest first: where the LOAM factors look for
/// neighbours on the right rings.
struct LoamCandidates {
  static constexpr std::size_t kMax = 8;
  std::size_t index[kMax];
  float squared_distance[kMax];
  std::size_t count = 0;
  /// Searches around x; true when at least `needed` were found and the nearest is within
  /// max_distance.
  bool search(const KdTree& tree, const Eigen::Vector3d& x, double max_distance,
              std::size_t needed) {
    count = tree.knn(x.cast<float>(), kMax, index, squared_distance);
    return count >= needed && !(squared_distance[0] > max_distance * max_distance);
  }
};

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
    LoamCandidates near;
    if (!near.search(tree, x, max_distance, 2)) return false;
    const std::size_t* idx = near.index;
    const std::size_t found = near.count;
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
