#pragma once
// k-d tree over a point cloud's positions (nanoflann), for nearest and k-nearest neighbours.

#include <cstddef>
#include <memory>
#include <vector>

#include "scanmatch/core/point_cloud.hpp"

namespace scanmatch {

class KdTree {
 public:
  /// Indexes `points` (kept by reference: they must outlive the tree and not change).
  explicit KdTree(const std::vector<Point>& points);
  ~KdTree();
  KdTree(KdTree&&) noexcept;

  /// Nearest point within sqrt(max_squared_distance); false when there is none.
  bool nearest(const Point& query, float max_squared_distance, std::size_t& index,
               float& squared_distance) const;
  /// The k nearest points (fewer when the cloud is smaller), closest first; returns the count.
  std::size_t knn(const Point& query, std::size_t k, std::size_t* indices,
                  float* squared_distances) const;
  std::size_t size() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace scanmatch
