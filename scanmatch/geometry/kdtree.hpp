#pragma once
// k-d trees (nanoflann) for nearest and k-nearest neighbours, one template for every dimension:
// KdTree over a point cloud's positions (3D, float), KdTree2 over 2D scan points (double).

#include <Eigen/Core>
#include <cstddef>
#include <memory>
#include <vector>

#include "scanmatch/core/point_cloud.hpp"

namespace scanmatch {

/// A k-d tree over fixed-size Eigen vectors (`PointT`: Eigen::Matrix<Scalar, Dim, 1>).
template <class PointT>
class BasicKdTree {
 public:
  using Scalar = typename PointT::Scalar;

  /// Indexes `points` (kept by reference: they must outlive the tree and not change).
  explicit BasicKdTree(const std::vector<PointT>& points);
  ~BasicKdTree();
  BasicKdTree(BasicKdTree&&) noexcept;

  /// Nearest point within sqrt(max_squared_distance); false when there is none.
  bool nearest(const PointT& query, Scalar max_squared_distance, std::size_t& index,
               Scalar& squared_distance) const;
  /// The k nearest points (fewer when there are fewer points), closest first; returns the count.
  std::size_t knn(const PointT& query, std::size_t k, std::size_t* indices,
                  Scalar* squared_distances) const;
  std::size_t size() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

using KdTree = BasicKdTree<Point>;
using KdTree2 = BasicKdTree<Eigen::Vector2d>;
// Defined for these two only (kdtree.cpp).
extern template class BasicKdTree<Point>;
extern template class BasicKdTree<Eigen::Vector2d>;

}  // namespace scanmatch
