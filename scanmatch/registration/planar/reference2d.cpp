#include "scanmatch/registration/planar/reference2d.hpp"

namespace scanmatch {

const KdTree2& Reference2D::tree() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (!tree_) tree_.emplace(scan_.points);
  return *tree_;
}

const PointGrid2& Reference2D::grid() const {
  // Cells of 0.2 m: a laser's pairs lie within a few cm, found in the 3 x 3 cells about the query.
  constexpr double kCell = 0.2;
  const std::lock_guard<std::mutex> lock(mutex_);
  if (!grid_) grid_.emplace(scan_.points, kCell);
  return *grid_;
}

const std::vector<FittedLine>& Reference2D::lines(double radius, double max_gap) const {
  const std::lock_guard<std::mutex> lock(mutex_);
  for (const auto& l : lines_)
    if (l->radius == radius && l->max_gap == max_gap) return l->lines;
  lines_.push_back(std::make_unique<const Lines>(
      Lines{radius, max_gap, fit_scan_lines(scan_, radius, max_gap)}));
  return lines_.back()->lines;
}

}  // namespace scanmatch
