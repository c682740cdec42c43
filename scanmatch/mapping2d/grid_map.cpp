#include "scanmatch/mapping2d/grid_map.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <utility>

#include "scanmatch/core/error.hpp"
#include "scanmatch/io/file_util.hpp"
#include "scanmatch/io/image.hpp"

namespace scanmatch {
namespace {

// Lattice indices stay well inside int so that extents and sums of them cannot overflow.
constexpr double kMaxCellIndex = double{1 << 30};
// Cells added on each side when the grid grows, so that a moving sensor does not reallocate the
// grid on every scan.
constexpr int kMinGrowthMargin = 64;
constexpr float kUnobserved = std::numeric_limits<float>::quiet_NaN();

// Lattice cell containing `p` given in cell units (world / resolution); caller checks the range.
Eigen::Vector2i floor_cell(const Eigen::Vector2d& p) {
  return {static_cast<int>(std::floor(p.x())), static_cast<int>(std::floor(p.y()))};
}

bool cell_index_in_range(const Eigen::Vector2d& p) {
  return std::abs(p.x()) < kMaxCellIndex && std::abs(p.y()) < kMaxCellIndex;
}

// Calls visit(index) with the storage index (`origin`: the lattice cell of index 0, `width`: cells
// a row) of every cell the segment a -> b (in cell units) passes through, from a's cell up to but
// excluding b's cell (Amanatides & Woo). The number of steps is fixed by the integer distance
// between the end cells, so rounding can never overshoot the end cell. Scalars and a running
// index: the rays of a long-range scan visit ~10^6 cells.
template <class Visit>
void for_each_index_before_end(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                               const Eigen::Vector2i& origin, std::int64_t width, Visit&& visit) {
  const Eigen::Vector2i cell = floor_cell(a);
  const Eigen::Vector2i end = floor_cell(b);
  const double dx = b.x() - a.x(), dy = b.y() - a.y();
  const int step_x = end.x() >= cell.x() ? 1 : -1, step_y = end.y() >= cell.y() ? 1 : -1;
  int remaining_x = std::abs(end.x() - cell.x()), remaining_y = std::abs(end.y() - cell.y());
  constexpr double kNever = std::numeric_limits<double>::infinity();
  // Ray parameter (0 at a, 1 at b) of the next boundary crossed along each axis, and between two
  // boundaries. An axis with steps remaining has a non-zero direction of the step's sign.
  double next_x = kNever, next_y = kNever, interval_x = kNever, interval_y = kNever;
  if (remaining_x != 0) {
    const double boundary = step_x > 0 ? cell.x() + 1.0 : cell.x();
    next_x = (boundary - a.x()) / dx;
    interval_x = 1.0 / std::abs(dx);
  }
  if (remaining_y != 0) {
    const double boundary = step_y > 0 ? cell.y() + 1.0 : cell.y();
    next_y = (boundary - a.y()) / dy;
    interval_y = 1.0 / std::abs(dy);
  }
  std::int64_t index =
      static_cast<std::int64_t>(cell.y() - origin.y()) * width + (cell.x() - origin.x());
  const std::int64_t row_step = step_y * width;
  while (remaining_x + remaining_y > 0) {
    visit(index);
    if (remaining_y == 0 || (remaining_x > 0 && next_x < next_y)) {
      index += step_x;
      next_x += interval_x;
      --remaining_x;
    } else {
      index += row_step;
      next_y += interval_y;
      --remaining_y;
    }
  }
}

}  // namespace

OccupancyGrid::OccupancyGrid(const GridMapOptions& options) : options_(options) {
  const auto require = [](bool ok, const std::string& problem) {
    if (!ok) fail("grid map options", problem);
  };
  const GridMapOptions& o = options;
  require(std::isfinite(o.resolution) && o.resolution > 0,
          "resolution must be positive, got " + std::to_string(o.resolution));
  require(o.max_cells > 0, "max_cells must be positive");
  require(std::isfinite(o.hit_log_odds) && o.hit_log_odds > 0,
          "hit_log_odds must be positive, got " + std::to_string(o.hit_log_odds));
  require(std::isfinite(o.miss_log_odds) && o.miss_log_odds < 0,
          "miss_log_odds must be negative, got " + std::to_string(o.miss_log_odds));
  require(std::isfinite(o.min_log_odds) && o.min_log_odds < 0,
          "min_log_odds must be negative, got " + std::to_string(o.min_log_odds));
  require(std::isfinite(o.max_log_odds) && o.max_log_odds > 0,
          "max_log_odds must be positive, got " + std::to_string(o.max_log_odds));
  require(
      o.free_threshold > 0 && o.free_threshold < o.occupied_threshold && o.occupied_threshold < 1,
      "thresholds must satisfy 0 < free_threshold < occupied_threshold < 1, got " +
          std::to_string(o.free_threshold) + " and " + std::to_string(o.occupied_threshold));
}

void OccupancyGrid::insert_scan(const Eigen::Isometry2d& sensor_pose,
                                const std::vector<Eigen::Vector2d>& hits_in_sensor_frame,
                                const std::vector<Eigen::Vector2d>& misses_in_sensor_frame) {
  if (!sensor_pose.matrix().allFinite()) return;
  // Everything in cell units from here on, divided exactly as index_of divides, so that a query at
  // a hit point finds the hit's cell even on a cell boundary.
  const double resolution = options_.resolution;
  const Eigen::Vector2d sensor = sensor_pose.translation() / resolution;
  const auto check_range = [&](const Eigen::Vector2d& p) {
    if (!cell_index_in_range(p))
      fail("occupancy grid", "point (" + std::to_string(p.x() * resolution) + ", " +
                                 std::to_string(p.y() * resolution) +
                                 ") m is too far from the origin for the grid");
  };
  check_range(sensor);
  const auto to_cells = [&](const std::vector<Eigen::Vector2d>& points) {
    std::vector<Eigen::Vector2d> out;
    out.reserve(points.size());
    for (const Eigen::Vector2d& p : points) {
      if (!p.allFinite()) continue;
      out.push_back(sensor_pose * p / resolution);
      check_range(out.back());
    }
    return out;
  };
  const std::vector<Eigen::Vector2d> hits = to_cells(hits_in_sensor_frame);
  const std::vector<Eigen::Vector2d> misses = to_cells(misses_in_sensor_frame);
  if (hits.empty() && misses.empty()) return;

  // A ray never leaves the bounding box of its end cells, so one growth covers the whole scan.
  Eigen::Vector2i low = floor_cell(sensor);
  Eigen::Vector2i high = low;
  for (const auto* points : {&hits, &misses})
    for (const Eigen::Vector2d& p : *points) {
      low = low.cwiseMin(floor_cell(p));
      high = high.cwiseMax(floor_cell(p));
    }
  ensure_contains(low, high);

  const auto storage_index = [&](const Eigen::Vector2i& cell) {
    return static_cast<std::int64_t>(cell.y() - origin_cell_.y()) * width_ +
           (cell.x() - origin_cell_.x());
  };
  // One update per cell and scan, hits winning over misses: each cell a ray touches is marked
  // (kFreeMark, then kHitMark over it) and listed once; the marks are cleared again at the end.
  // Cheaper than sorting every ray's cells, and each cell gets the same single update.
  constexpr std::uint8_t kUntouched = 0, kFreeMark = 1, kHitMark = 2;
  if (scan_marks_.size() != log_odds_.size()) scan_marks_.assign(log_odds_.size(), kUntouched);
  std::vector<std::int64_t> touched;
  touched.reserve(8 * (hits.size() + misses.size()));
  const auto mark = [&](std::int64_t index, std::uint8_t kind) {
    std::uint8_t& m = scan_marks_[static_cast<std::size_t>(index)];
    if (m == kUntouched) touched.push_back(index);
    m = std::max(m, kind);
  };
  const auto add_free = [&](std::int64_t index) { mark(index, kFreeMark); };
  for (const Eigen::Vector2d& hit : hits) {
    for_each_index_before_end(sensor, hit, origin_cell_, width_, add_free);
    mark(storage_index(floor_cell(hit)), kHitMark);
  }
  for (const Eigen::Vector2d& miss : misses) {
    for_each_index_before_end(sensor, miss, origin_cell_, width_, add_free);
    add_free(storage_index(floor_cell(miss)));
  }
  for (const std::int64_t index : touched) {
    std::uint8_t& m = scan_marks_[static_cast<std::size_t>(index)];
    float& cell = log_odds_[static_cast<std::size_t>(index)];
    const double before = std::isnan(cell) ? 0.0 : cell;
    const double delta = m == kHitMark ? options_.hit_log_odds : options_.miss_log_odds;
    cell = static_cast<float>(
        std::clamp(before + delta, options_.min_log_odds, options_.max_log_odds));
    m = kUntouched;
  }
}

void OccupancyGrid::ensure_contains(const Eigen::Vector2i& low, const Eigen::Vector2i& high) {
  const bool empty = log_odds_.empty();
  const Eigen::Vector2i old_low = origin_cell_;
  const Eigen::Vector2i old_high = origin_cell_ + Eigen::Vector2i(width_ - 1, height_ - 1);
  if (!empty && (low.array() >= old_low.array()).all() && (high.array() <= old_high.array()).all())
    return;

  // Union of the old and the needed rectangles, widened by `margin` on each side that grows.
  const auto bounds = [&](const Eigen::Vector2i& margin) {
    Eigen::Vector2i new_low = low - margin, new_high = high + margin;
    if (!empty) {
      for (int axis = 0; axis < 2; ++axis) {
        new_low[axis] = low[axis] < old_low[axis] ? low[axis] - margin[axis] : old_low[axis];
        new_high[axis] = high[axis] > old_high[axis] ? high[axis] + margin[axis] : old_high[axis];
      }
    }
    return std::pair{new_low, new_high};
  };
  const auto cell_count = [](const std::pair<Eigen::Vector2i, Eigen::Vector2i>& b) {
    return (static_cast<std::int64_t>(b.second.x()) - b.first.x() + 1) *
           (static_cast<std::int64_t>(b.second.y()) - b.first.y() + 1);
  };
  // Growing by half the current size keeps the number of reallocations logarithmic. Near the
  // cell limit the margin shrinks to what still fits rather than to nothing: grown to the scan
  // alone, a large map (freiburg-campus's odometry, 85 million cells) was copied again at most of
  // the scans that reached past it, half of the run's time.
  Eigen::Vector2i margin(std::max(kMinGrowthMargin, width_ / 2),
                         std::max(kMinGrowthMargin, height_ / 2));
  auto new_bounds = bounds(margin);
  const auto max_cells = static_cast<std::int64_t>(
      std::min<std::size_t>(options_.max_cells, std::numeric_limits<std::int64_t>::max()));
  while (cell_count(new_bounds) > max_cells && (margin.x() > 0 || margin.y() > 0)) {
    margin /= 2;
    new_bounds = bounds(margin);
  }
  if (cell_count(new_bounds) > max_cells)
    fail("occupancy grid",
         "covering the scan needs " + std::to_string(cell_count(new_bounds)) +
             " cells, more than the limit of " + std::to_string(max_cells) +
             " (a point far from the others, or a resolution too fine for the area)");

  const auto& [new_low, new_high] = new_bounds;
  const int new_width = new_high.x() - new_low.x() + 1;
  const int new_height = new_high.y() - new_low.y() + 1;
  std::vector<float> grown(static_cast<std::size_t>(new_width) * new_height, kUnobserved);
  const Eigen::Vector2i shift = origin_cell_ - new_low;
  for (int row = 0; row < height_; ++row)
    std::copy_n(
        log_odds_.begin() + static_cast<std::ptrdiff_t>(row) * width_, width_,
        grown.begin() + static_cast<std::ptrdiff_t>(row + shift.y()) * new_width + shift.x());
  log_odds_ = std::move(grown);
  origin_cell_ = new_low;
  width_ = new_width;
  height_ = new_height;
}

std::int64_t OccupancyGrid::index_of(const Eigen::Vector2d& world) const {
  const Eigen::Vector2d p = world / options_.resolution;
  if (!p.allFinite() || !cell_index_in_range(p)) return -1;
  const Eigen::Vector2i cell = floor_cell(p) - origin_cell_;
  if (cell.x() < 0 || cell.y() < 0 || cell.x() >= width_ || cell.y() >= height_) return -1;
  return static_cast<std::int64_t>(cell.y()) * width_ + cell.x();
}

double OccupancyGrid::probability(const Eigen::Vector2d& world) const {
  const std::int64_t index = index_of(world);
  if (index < 0) return 0.5;
  const float log_odds = log_odds_[static_cast<std::size_t>(index)];
  return std::isnan(log_odds) ? 0.5 : log_odds_to_probability(log_odds);
}

bool OccupancyGrid::observed(const Eigen::Vector2d& world) const {
  const std::int64_t index = index_of(world);
  return index >= 0 && !std::isnan(log_odds_[static_cast<std::size_t>(index)]);
}

CellState OccupancyGrid::state(const Eigen::Vector2d& world) const {
  const double p = probability(world);
  if (p > options_.occupied_threshold) return CellState::kOccupied;
  if (p < options_.free_threshold) return CellState::kFree;
  return CellState::kUnknown;
}

Eigen::Vector2d OccupancyGrid::cell_centre(int column, int row) const {
  return (origin_cell_.cast<double>() + Eigen::Vector2d(column + 0.5, row + 0.5)) *
         options_.resolution;
}

std::vector<Eigen::Vector2d> OccupancyGrid::occupied_cell_centres() const {
  std::vector<Eigen::Vector2d> centres;
  for (int row = 0; row < height_; ++row)
    for (int column = 0; column < width_; ++column) {
      const float log_odds = log_odds_[static_cast<std::size_t>(row) * width_ + column];
      if (!std::isnan(log_odds) && log_odds_to_probability(log_odds) > options_.occupied_threshold)
        centres.push_back(cell_centre(column, row));
    }
  return centres;
}

void OccupancyGrid::crop_to_observed(int margin) {
  int min_x = width_, min_y = height_, max_x = -1, max_y = -1;
  for (int row = 0; row < height_; ++row)
    for (int column = 0; column < width_; ++column)
      if (!std::isnan(log_odds_[static_cast<std::size_t>(row) * static_cast<std::size_t>(width_) +
                                static_cast<std::size_t>(column)])) {
        min_x = std::min(min_x, column);
        max_x = std::max(max_x, column);
        min_y = std::min(min_y, row);
        max_y = std::max(max_y, row);
      }
  if (max_x < 0) return;
  margin = std::max(0, margin);
  min_x = std::max(0, min_x - margin);
  min_y = std::max(0, min_y - margin);
  max_x = std::min(width_ - 1, max_x + margin);
  max_y = std::min(height_ - 1, max_y + margin);
  const int new_width = max_x - min_x + 1, new_height = max_y - min_y + 1;
  std::vector<float> cropped(static_cast<std::size_t>(new_width) *
                             static_cast<std::size_t>(new_height));
  for (int row = 0; row < new_height; ++row)
    std::copy_n(log_odds_.begin() + static_cast<std::ptrdiff_t>(row + min_y) * width_ + min_x,
                new_width, cropped.begin() + static_cast<std::ptrdiff_t>(row) * new_width);
  log_odds_ = std::move(cropped);
  origin_cell_ += Eigen::Vector2i(min_x, min_y);
  width_ = new_width;
  height_ = new_height;
}

}  // namespace scanmatch
