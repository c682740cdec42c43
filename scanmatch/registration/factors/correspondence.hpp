#pragma once
// The correspondence search of the k-d tree factors (point-to-plane, point-to-line, GICP, LOAM's
// edges and planes): a source point moved by the pose, its nearest target points in the target's
// k-d tree, and the distance gate. A factor derives from NearestTargetSearch and adds only its
// residual and Jacobian.

#include <Eigen/Core>
#include <array>
#include <cstddef>

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/core/se3.hpp"
#include "scanmatch/geometry/kdtree.hpp"

namespace scanmatch {

/// A source point and its K nearest target points (NearestTargetSearch::search).
template <std::size_t K>
struct NearestTargets {
  Eigen::Vector3d p;                 ///< the source point (source frame)
  Eigen::Vector3d x;                 ///< T p
  std::array<std::size_t, K> index;  ///< target points, closest first; the first `count` are set
  std::size_t count = 0;
};

/// What the k-d tree factors hold: the source, the target with its k-d tree, and the gate.
struct NearestTargetSearch {
  const PointCloud& source;
  const PointCloud& target;
  const KdTree& tree;   ///< over target.points
  double max_distance;  ///< m: a point whose nearest target point is farther has no correspondence

  std::size_t size() const { return source.size(); }
  /// Moves source point i by T and finds its K nearest target points; false when fewer than
  /// `needed` exist or the nearest is farther than max_distance (compared in double).
  template <std::size_t K>
  bool search(const Pose& T, std::size_t i, NearestTargets<K>& near, std::size_t needed = K) const {
    const Eigen::Vector3d p = source.points[i].cast<double>(), x = T * p;
    near.p = p;
    near.x = x;
    std::array<float, K> squared_distance;
    near.count = tree.knn(x.cast<float>(), K, near.index.data(), squared_distance.data());
    return near.count >= needed && !(squared_distance[0] > max_distance * max_distance);
  }
};

}  // namespace scanmatch
