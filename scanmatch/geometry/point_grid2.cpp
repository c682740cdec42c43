#include "scanmatch/geometry/point_grid2.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "scanmatch/core/error.hpp"

namespace scanmatch {
namespace {
// Cells at most: a scan's stray far return must not make the grid huge (the cells coarsen).
constexpr double kMaxCells = 4e6;
// Rings of cells looked at most; a query that needs more (a wide radius with nothing near)
// looks at every point instead, which costs less than the rings would.
constexpr long kMaxRings = 32;
}  // namespace

PointGrid2::PointGrid2(const std::vector<Eigen::Vector2d>& points, double cell) : cell_(cell) {
  if (!(cell > 0.0) || !std::isfinite(cell))
    throw Error("point grid: the cell size must be positive and finite");
  if (points.size() >= std::numeric_limits<std::uint32_t>::max())
    throw Error("point grid: too many points");
  Eigen::Vector2d low = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d high = -low;
  for (const Eigen::Vector2d& p : points) {
    if (!p.allFinite()) continue;
    low = low.cwiseMin(p);
    high = high.cwiseMax(p);
    ++size_;
  }
  if (size_ == 0) return;
  const Eigen::Vector2d extent = high - low;
  // Points spanning more than a double holds (coordinates near 1e308): one cell, looked at whole.
  one_cell_ = !extent.allFinite();
  if (!one_cell_) {
    const auto cells = [&](double c) { return (extent.x() / c + 1) * (extent.y() / c + 1); };
    while (cells(cell_) > kMaxCells) cell_ *= 2;
    origin_ = low;
    width_ = static_cast<long>(extent.x() / cell_) + 1;
    height_ = static_cast<long>(extent.y() / cell_) + 1;
  } else {
    width_ = height_ = 1;
  }
  const auto cell_of = [&](const Eigen::Vector2d& p) -> std::size_t {
    if (one_cell_) return 0;
    const long x = std::min(static_cast<long>((p.x() - low.x()) / cell_), width_ - 1);
    const long y = std::min(static_cast<long>((p.y() - low.y()) / cell_), height_ - 1);
    return static_cast<std::size_t>(y * width_ + x);
  };
  // Counting sort by cell, stable: each cell's points keep their input order.
  cell_start_.assign(static_cast<std::size_t>(width_ * height_) + 1, 0);
  for (const Eigen::Vector2d& p : points)
    if (p.allFinite()) ++cell_start_[cell_of(p) + 1];
  for (std::size_t c = 1; c < cell_start_.size(); ++c) cell_start_[c] += cell_start_[c - 1];
  std::vector<std::uint32_t> next(cell_start_.begin(), cell_start_.end() - 1);
  sorted_.resize(size_);
  index_.resize(size_);
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) continue;
    const std::uint32_t at = next[cell_of(points[i])]++;
    sorted_[at] = points[i];
    index_[at] = static_cast<std::uint32_t>(i);
  }
}

bool PointGrid2::nearest(const Eigen::Vector2d& query, double max_squared_distance,
                         std::size_t& index, double& squared_distance) const {
  if (size_ == 0 || !query.allFinite() || !(max_squared_distance >= 0.0)) return false;
  double best = std::numeric_limits<double>::infinity();
  std::uint32_t best_index = 0;
  // Sorted points [begin, end): the nearer, or of equally near ones the first in the input.
  const auto look_at = [&](std::uint32_t begin, std::uint32_t end) {
    for (std::uint32_t i = begin; i < end; ++i) {
      const double d = (sorted_[i] - query).squaredNorm();
      if (d < best || (d == best && index_[i] < best_index)) {
        best = d;
        best_index = index_[i];
      }
    }
  };
  const double radius = std::sqrt(max_squared_distance);
  const long rings = static_cast<long>(std::ceil(radius / cell_)) + 1;
  bool settled = false;
  if (!one_cell_) {
    // The query's cell, possibly off the grid; clamped so that a far query cannot overflow.
    const auto cell_index = [&](double v, double low, long cells) {
      const double c = std::floor((v - low) / cell_);
      return static_cast<long>(std::clamp(c, -1.0 - radius / cell_ - 1.0,
                                          static_cast<double>(cells) + radius / cell_ + 1.0));
    };
    const long qx = cell_index(query.x(), origin_.x(), width_);
    const long qy = cell_index(query.y(), origin_.y(), height_);
    // The query within its cell. Where it lies inside it (not clamped), cells and rings can be
    // ruled out by their distance from it, taken a hair short (`slack`) so that a point rounded
    // into its cell is never ruled out.
    const double fx = query.x() - origin_.x() - static_cast<double>(qx) * cell_;
    const double fy = query.y() - origin_.y() - static_cast<double>(qy) * cell_;
    const double slack = 1e-9 * (1.0 + std::abs(query.x()) + std::abs(query.y()));
    const double edge = std::min({fx, cell_ - fx, fy, cell_ - fy}) - slack;
    const bool inside = edge >= 0.0;
    // The distance along one axis from the query to the cell `d` cells from its own.
    const auto gap = [&](long d, double f) {
      if (d == 0) return 0.0;
      const double g =
          d > 0 ? static_cast<double>(d) * cell_ - f : f + static_cast<double>(-d - 1) * cell_;
      return std::max(0.0, g - slack);
    };
    const auto visit = [&](long dx, long dy) {
      const long x = qx + dx, y = qy + dy;
      if (x < 0 || y < 0 || x >= width_ || y >= height_) return;
      const auto c = static_cast<std::size_t>(y * width_ + x);
      const std::uint32_t begin = cell_start_[c], end = cell_start_[c + 1];
      if (begin == end) return;
      // A full cell is looked at only when it could hold a point as near as the best so far
      // (for a few points the test costs more than it saves).
      if (inside && end - begin > 3) {
        const double gx = gap(dx, fx), gy = gap(dy, fy);
        if (gx * gx + gy * gy > best) return;
      }
      look_at(begin, end);
    };
    // Ring k holds the cells k away (Chebyshev) from the query's; the points beyond it lie at
    // least k cells away, and from a query inside its cell `edge` further.
    for (long k = 0; k <= std::min(rings, kMaxRings); ++k) {
      if (k == 0) {
        visit(0, 0);
      } else {
        for (long d = -k; d <= k; ++d) {
          visit(d, -k);
          visit(d, k);
        }
        for (long d = -k + 1; d <= k - 1; ++d) {
          visit(-k, d);
          visit(k, d);
        }
      }
      const double reach = static_cast<double>(k) * cell_ + (inside ? edge : 0.0);
      if (best < reach * reach || reach > radius) {
        settled = true;
        break;
      }
    }
  }
  if (!settled) look_at(0, static_cast<std::uint32_t>(sorted_.size()));
  if (!(best <= max_squared_distance)) return false;
  index = best_index;
  squared_distance = best;
  return true;
}

}  // namespace scanmatch
