#pragma once
// Exact nearest-neighbour queries within a radius over 2D points, on a uniform grid of square
// cells whose points are stored cell by cell. Built in linear time (a counting sort): loop closure
// registers each candidate once onto a submap of 13 scans made for it, and building a k-d tree
// of that submap cost as much as half of the registration.

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace scanmatch {

class PointGrid2 {
 public:
  /// Indexes `points` (copied) in cells of `cell` m, coarser where their extent would need more
  /// than a few million cells. Non-finite points are never found. Throws Error unless `cell` is
  /// positive and finite.
  PointGrid2(const std::vector<Eigen::Vector2d>& points, double cell);

  /// The point nearest to `query` within sqrt(max_squared_distance) (of equally near ones, the
  /// first in `points`); false when there is none.
  bool nearest(const Eigen::Vector2d& query, double max_squared_distance, std::size_t& index,
               double& squared_distance) const;

  std::size_t size() const { return size_; }
  double cell() const { return cell_; }

 private:
  double cell_ = 1.0;
  Eigen::Vector2d origin_ = Eigen::Vector2d::Zero();  ///< corner of cell (0, 0)
  long width_ = 0, height_ = 0;
  std::size_t size_ = 0;
  bool one_cell_ = false;  ///< the points' extent overflows a double: every query looks at all
  std::vector<std::uint32_t> cell_start_;  ///< cell c's points: sorted_[cell_start_[c] ..]
  std::vector<Eigen::Vector2d> sorted_;    ///< the finite points, cell by cell, in input order
  std::vector<std::uint32_t> index_;       ///< each sorted point's index in the input
};

}  // namespace scanmatch
