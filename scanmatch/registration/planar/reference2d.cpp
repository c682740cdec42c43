#include "scanmatch/registration/planar/reference2d.hpp"

namespace scanmatch {

const KdTree2& Reference2D::tree() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (!tree_) tree_.emplace(scan_.points);
  return *tree_;
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
