#include "scanmatch/registration/planar/correlative_search.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "scanmatch/core/error.hpp"

namespace scanmatch {
namespace {

using Vec2 = Eigen::Vector2d;

/// The branch and bound's levels: each level's cell bounds the kBranch x kBranch cells of the
/// level below it, so level k's blocks have side kSides[k] = kBranch^k.
constexpr int kBranch = 4;
constexpr int kLevels = 4;
constexpr std::array<int, kLevels> kSides = {1, kBranch, kBranch* kBranch,
                                             kBranch* kBranch* kBranch};
constexpr int kTopSide = kSides[kLevels - 1];
constexpr std::int64_t kMaxCells = 16'000'000;

struct LikelihoodGrid {
  double resolution = 0.05;
  Vec2 origin = Vec2::Zero();  ///< world position of cell (0, 0)'s corner
  int width = 0, height = 0;
  /// levels[0] is the smoothed likelihood; levels[k](x, y) = max of levels[0] over the square of
  /// side kBranch^k from (x, y) towards +x and +y.
  std::vector<std::vector<float>> levels;

  float at(int level, int x, int y) const {
    if (x < 0 || y < 0 || x >= width || y >= height) return 0.0f;
    return levels[static_cast<std::size_t>(level)]
                 [static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
                  static_cast<std::size_t>(x)];
  }
};

/// The grid spans the reference points only: a current point landing elsewhere scores nothing.
/// Below them it reaches one top block further, so that the levels bound the blocks that start
/// outside (`g.at` is zero off the grid). Coarser cells where the area is huge, so memory stays
/// bounded.
LikelihoodGrid make_grid(const std::vector<Vec2>& reference, double resolution) {
  LikelihoodGrid g;
  Vec2 low = reference.front(), high = reference.front();
  for (const Vec2& p : reference) {
    low = low.cwiseMin(p);
    high = high.cwiseMax(p);
  }
  const auto cells = [&](double r) {
    const Vec2 size = high - low;
    return (size.x() / r + kTopSide + 6) * (size.y() / r + kTopSide + 6) * kLevels;
  };
  while (cells(resolution) > static_cast<double>(kMaxCells)) resolution *= 2;
  low -= Vec2::Constant((kTopSide + 3) * resolution);
  high += Vec2::Constant(3 * resolution);
  const Vec2 size = high - low;
  g.resolution = resolution;
  g.origin = low;
  g.width = static_cast<int>(std::ceil(size.x() / resolution)) + 1;
  g.height = static_cast<int>(std::ceil(size.y() / resolution)) + 1;
  const std::size_t n = static_cast<std::size_t>(g.width) * static_cast<std::size_t>(g.height);
  g.levels.assign(kLevels, {});
  std::vector<float>& fine = g.levels[0];
  fine.assign(n, 0.0f);
  const auto index = [&](int x, int y) {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(g.width) +
           static_cast<std::size_t>(x);
  };
  // Gaussian of sigma = one cell around each reference point, out to two cells.
  const int radius = 2;
  float kernel[2 * radius + 1][2 * radius + 1];
  for (int dy = -radius; dy <= radius; ++dy)
    for (int dx = -radius; dx <= radius; ++dx)
      kernel[dy + radius][dx + radius] = static_cast<float>(std::exp(-0.5 * (dx * dx + dy * dy)));
  for (const Vec2& p : reference) {
    const int cx = static_cast<int>(std::floor((p.x() - low.x()) / resolution));
    const int cy = static_cast<int>(std::floor((p.y() - low.y()) / resolution));
    for (int dy = -radius; dy <= radius; ++dy)
      for (int dx = -radius; dx <= radius; ++dx) {
        const int x = cx + dx, y = cy + dy;
        if (x < 0 || y < 0 || x >= g.width || y >= g.height) continue;
        float& cell = fine[index(x, y)];
        cell = std::max(cell, kernel[dy + radius][dx + radius]);
      }
  }
  // Each level from the one below: the maximum of kBranch cells `stride` apart along +x, then
  // +y. Off the grid counts as zero; written branch-free over whole rows so that it vectorizes.
  const std::size_t width = static_cast<std::size_t>(g.width);
  std::vector<float> rows(n);
  std::size_t stride = 1;
  for (std::size_t level = 1; level < kLevels; ++level, stride *= kBranch) {
    const std::vector<float>& below = g.levels[level - 1];
    for (std::size_t y = 0; y < static_cast<std::size_t>(g.height); ++y) {
      const float* in = below.data() + y * width;
      float* out = rows.data() + y * width;
      std::copy(in, in + width, out);
      for (std::size_t k = 1; k < kBranch && k * stride < width; ++k) {
        const float* shifted = in + k * stride;
        const std::size_t count = width - k * stride;
        for (std::size_t x = 0; x < count; ++x) out[x] = std::max(out[x], shifted[x]);
      }
    }
    std::vector<float>& out = g.levels[level];
    out.resize(n);
    for (std::size_t y = 0; y < static_cast<std::size_t>(g.height); ++y) {
      float* row = out.data() + y * width;
      std::copy(rows.data() + y * width, rows.data() + (y + 1) * width, row);
      for (std::size_t k = 1; k < kBranch; ++k) {
        const std::size_t other = y + k * stride;
        if (other >= static_cast<std::size_t>(g.height)) break;
        const float* in = rows.data() + other * width;
        for (std::size_t x = 0; x < width; ++x) row[x] = std::max(row[x], in[x]);
      }
    }
  }
  return g;
}

/// The current scan thinned to one point per cell: the score counts surface, not point density.
std::vector<Vec2> thinned(const std::vector<Vec2>& points, double cell) {
  // Cells as (x, y) pairs, clamped so that a wild coordinate cannot overflow the conversion.
  const auto index = [&](double v) {
    return static_cast<std::int64_t>(std::floor(std::clamp(v / cell, -1e15, 1e15)));
  };
  struct Key {
    std::int64_t x, y;
    std::size_t point;
  };
  std::vector<Key> keys;
  keys.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    keys.push_back({index(points[i].x()), index(points[i].y()), i});
  std::sort(keys.begin(), keys.end(), [](const Key& a, const Key& b) {
    return a.x != b.x ? a.x < b.x : (a.y != b.y ? a.y < b.y : a.point < b.point);
  });
  std::vector<Vec2> out;
  for (std::size_t k = 0; k < keys.size(); ++k)
    if (k == 0 || keys[k].x != keys[k - 1].x || keys[k].y != keys[k - 1].y)
      out.push_back(points[keys[k].point]);
  return out;
}

void check_window(double window, double angle_window, double resolution) {
  if (!(window > 0.0) || !(angle_window >= 0.0) || !(resolution > 0.0))
    throw Error("correlative search: window and resolution must be positive");
}

/// A block of translations (corner x, y in cells from the window's -half, side kSides[level]) at
/// one rotation, with the upper bound of their scores at that level.
struct Block {
  float bound;
  int angle, level, x, y;
};
bool higher_bound(const Block& a, const Block& b) {
  return a.bound > b.bound;
}

/// What a search over a window scores: the current scan thinned, the reference's likelihood grid
/// and the thinned points' cells under each rotation. Empty `cells` when nothing can be scored.
struct SearchSpace {
  std::vector<Vec2> points;
  std::shared_ptr<const LikelihoodGrid> grid_owner;
  const LikelihoodGrid* grid_ = nullptr;
  Pose2 initial = Pose2::Identity();
  double angle_step = 0.0;
  int angles = 0;              ///< rotations -angles..angles steps about the initial guess
  int half_x = 0, half_y = 0;  ///< translations -half..half cells about it, along x and y
  int span_x = 0, span_y = 0;  ///< 2 * half + 1
  std::vector<std::vector<std::pair<int, int>>> cells;  ///< per rotation, relative to -half

  /// Sum over the points of the level's likelihood, at translation cell (x, y) (0..span-1).
  float score(int angle, int level, int x, int y) const {
    float sum = 0.0f;
    for (const auto& [cx, cy] : cells[static_cast<std::size_t>(angle + angles)])
      sum += grid_->at(level, cx + x, cy + y);
    return sum;
  }
  const LikelihoodGrid& grid() const { return *grid_; }
  Pose2 pose(int angle, int x, int y) const {
    const double r = grid_->resolution;
    return pose2(initial.translation().x() + (x - half_x) * r,
                 initial.translation().y() + (y - half_y) * r,
                 pose2_angle(initial) + angle * angle_step);
  }
};

/// The current scan's points (finite, thinned at `resolution`'s double) and their ranges' 90th
/// percentile and maximum, for the search's angular step and the grid's footprint.
struct SearchPoints {
  std::vector<Vec2> points;
  double step_range = 0.0, max_range = 0.0;
};

SearchPoints search_points(const Scan2D& current, double resolution) {
  SearchPoints out;
  std::vector<Vec2>& points = out.points;
  // A non-finite point lands nowhere; dropped here, before any conversion to a cell.
  std::vector<Vec2> finite;
  finite.reserve(current.points.size());
  for (const Vec2& p : current.points)
    if (p.allFinite()) finite.push_back(p);
  points = thinned(finite, 2 * resolution);
  if (points.empty()) return out;
  double& max_range = out.max_range;
  std::vector<double> ranges;
  ranges.reserve(points.size());
  for (const Vec2& p : points) {
    ranges.push_back(p.norm());
    max_range = std::max(max_range, ranges.back());
  }
  // The angular step follows the 90th percentile of the ranges, not the farthest point: the few
  // far returns (30 to 80 m on ACES) would otherwise set a 0.1 deg step. On the three CARMEN logs
  // this searched 1.7x faster with the same failures (27 / 69 / 9 against 27 / 68 / 10).
  const auto percentile = ranges.begin() + static_cast<std::ptrdiff_t>(ranges.size() * 9 / 10);
  std::nth_element(ranges.begin(), percentile, ranges.end());
  out.step_range = *percentile;
  return out;
}

/// The rotations and translations of a search about `initial` onto `grid`, with the cells of the
/// points under each rotation.
SearchSpace search_space(SearchPoints&& current, std::shared_ptr<const LikelihoodGrid> grid,
                         const Pose2& initial, const Vec2& window, double angle_window) {
  SearchSpace space;
  space.points = std::move(current.points);
  const std::vector<Vec2>& points = space.points;
  space.grid_owner = std::move(grid);
  space.grid_ = space.grid_owner.get();
  const LikelihoodGrid& g = *space.grid_;
  const double r = g.resolution;
  const double step_range = current.step_range;

  // Angular step: a point at `step_range` moves by about one cell.
  space.angle_step = std::clamp(r / std::max(step_range, 1e-3), 0.1 * M_PI / 180, 1.0 * M_PI / 180);
  space.angles = static_cast<int>(std::ceil(angle_window / space.angle_step));
  space.half_x = static_cast<int>(std::ceil(window.x() / r));  // translations -half..half cells
  space.half_y = static_cast<int>(std::ceil(window.y() / r));
  space.span_x = 2 * space.half_x + 1;
  space.span_y = 2 * space.half_y + 1;
  space.initial = initial;
  const int angles = space.angles, half_x = space.half_x, half_y = space.half_y;

  // Cells of the thinned points under each rotation, relative to the window's corner.
  space.cells.resize(static_cast<std::size_t>(2 * angles + 1));
  // floor() through a shift into positive numbers (a plain conversion truncates): far cheaper
  // than std::floor, exact within 2^20 cells of the grid; farther (a wild point) is clamped, still
  // off the grid, where a conversion would overflow.
  constexpr double kShift = 1 << 20;
  const auto cell = [&](double v, int half) {
    return static_cast<int>(std::clamp(v, -kShift, kShift) + kShift) - (1 << 20) - half;
  };
  const Vec2 start = (initial.translation() - g.origin) / r;
  for (int a = -angles; a <= angles; ++a) {
    const double theta = pose2_angle(initial) + a * space.angle_step;
    const double c = std::cos(theta) / r, s = std::sin(theta) / r;
    auto& out = space.cells[static_cast<std::size_t>(a + angles)];
    out.reserve(points.size());
    for (const Vec2& p : points)
      out.push_back({cell(c * p.x() - s * p.y() + start.x(), half_x),
                     cell(s * p.x() + c * p.y() + start.y(), half_y)});
  }
  return space;
}

/// A search about `initial` onto `reference`'s filled surfaces where the current scan can land
/// (its footprint under `initial`, grown by the window and the rotation's sweep). Empty `cells`
/// when nothing can be scored.
SearchSpace search_space(const Scan2D& current, const Scan2D& reference, const Pose2& initial,
                         double window, double angle_window, double resolution, double fill_gap) {
  if (current.points.empty() || reference.points.empty()) return {};  // nothing to score
  SearchPoints points = search_points(current, resolution);
  if (points.points.empty()) return {};
  Vec2 low = initial.translation(), high = initial.translation();
  for (const Vec2& p : points.points) {
    const Vec2 q = initial * p;
    low = low.cwiseMin(q);
    high = high.cwiseMax(q);
  }
  const double margin =
      window + std::min(points.max_range, points.max_range * angle_window) + 4 * resolution;
  low -= Vec2::Constant(margin);
  high += Vec2::Constant(margin);
  std::vector<Vec2> useful;
  for (const Vec2& q : filled_surfaces(reference, fill_gap, resolution))
    if ((q.array() >= low.array()).all() && (q.array() <= high.array()).all()) useful.push_back(q);
  if (useful.empty()) return {};
  return search_space(std::move(points),
                      std::make_shared<LikelihoodGrid>(make_grid(useful, resolution)), initial,
                      Vec2::Constant(window), angle_window);
}

}  // namespace

struct CorrelativeGrid::Impl {
  std::shared_ptr<const LikelihoodGrid> grid;
};

CorrelativeGrid::CorrelativeGrid(const Scan2D& reference, double resolution, double fill_gap)
    : requested_resolution_(resolution) {
  if (!(resolution > 0.0)) throw Error("correlative search: resolution must be positive");
  std::vector<Vec2> surfaces;
  for (const Vec2& q : filled_surfaces(reference, fill_gap, resolution))
    if (q.allFinite()) surfaces.push_back(q);
  if (surfaces.empty()) return;
  auto impl = std::make_shared<Impl>();
  impl->grid = std::make_shared<LikelihoodGrid>(make_grid(surfaces, resolution));
  impl_ = std::move(impl);
}

namespace {

SearchSpace search_space(const Scan2D& current, const CorrelativeGrid& reference,
                         const Pose2& initial, const Vec2& window, double angle_window) {
  if (current.points.empty() || reference.empty()) return {};
  SearchPoints points = search_points(current, reference.resolution());
  if (points.points.empty()) return {};
  return search_space(std::move(points), reference.impl().grid, initial, window, angle_window);
}

}  // namespace

std::vector<Vec2> filled_surfaces(const Scan2D& scan, double max_gap, double step) {
  std::vector<Vec2> out = scan.points;
  const long m = static_cast<long>(scan.points.size());
  if (!(max_gap > 0.0) || !(step > 0.0) || m < 3) return out;
  const auto point = [&](long k) -> const Vec2& {
    return scan.points[static_cast<std::size_t>(k)];
  };
  // Whether `k` lies on the line through a and b (within 3 % of their distance, 5 cm at least).
  const auto on_line = [&](long k, const Vec2& a, const Vec2& b) {
    if (k < 0) return false;
    const Vec2 d = b - a;
    const double length = d.norm();
    const double off = std::abs(d.x() * (point(k) - a).y() - d.y() * (point(k) - a).x()) / length;
    return off <= std::max(0.05, 0.03 * length);
  };
  for (long i = 0; i < m; ++i) {
    const long j = beam_neighbour(m, scan.circular, i, 1);
    if (j < 0) continue;
    const Vec2 &a = point(i), &b = point(j);
    const double gap = (b - a).norm();
    if (gap <= step || gap > max_gap) continue;
    if (!on_line(beam_neighbour(m, scan.circular, i, -1), a, b) &&
        !on_line(beam_neighbour(m, scan.circular, j, 1), a, b))
      continue;
    const int pieces = static_cast<int>(std::ceil(gap / step));
    for (int k = 1; k < pieces; ++k) out.push_back(a + (b - a) * (static_cast<double>(k) / pieces));
  }
  return out;
}

Pose2 correlative_search(const Scan2D& current, const Scan2D& reference, const Pose2& initial,
                         double window, double angle_window, double resolution, double fill_gap) {
  return correlative_match(current, reference, initial, window, angle_window, resolution, fill_gap)
      .pose;
}

namespace {

void check_min_score(double min_score) {
  if (!(min_score >= 0.0 && min_score <= 1.0))
    throw Error("correlative search: the minimum score must be in [0, 1]");
}

/// correlative_match over a prepared search space.
CorrelativeMatch best_in(const SearchSpace& space, const Pose2& initial, double min_score) {
  CorrelativeMatch match;
  match.pose = initial;
  if (space.cells.empty()) return match;
  const std::vector<Vec2>& points = space.points;
  const int angles = space.angles, half_x = space.half_x, half_y = space.half_y,
            span_x = space.span_x, span_y = space.span_y;
  // Branch and bound, depth first: a block of translations is bounded by its level's maxima; the
  // children of the most promising blocks are looked at first, so the best score found early
  // dismisses most of the window. Exact at the finest level; ties go to the translation nearest
  // the guess.
  const auto bound_of = [&](int angle, int level, int x, int y) {
    return Block{space.score(angle, level, x, y), angle, level, x, y};
  };
  // The top level: the coarsest whose blocks still split the window.
  int top = kLevels - 1;
  while (top > 0 && kSides[static_cast<std::size_t>(top - 1)] >= std::max(span_x, span_y)) --top;
  const int top_side = kSides[static_cast<std::size_t>(top)];
  std::vector<Block> blocks;
  for (int a = -angles; a <= angles; ++a)
    for (int y = 0; y < span_y; y += top_side)
      for (int x = 0; x < span_x; x += top_side) blocks.push_back(bound_of(a, top, x, y));
  std::sort(blocks.begin(), blocks.end(), higher_bound);
  // Below the minimum nothing counts, so the bounds prune from the start.
  float best = static_cast<float>(min_score * static_cast<double>(points.size()));
  int best_a = 0, best_x = half_x, best_y = half_y;
  double best_offset = std::numeric_limits<double>::infinity();
  // A pose's exact score at the finest level; kept when it beats the best so far, or ties it
  // nearer the guess.
  const auto consider = [&](const Block& leaf) {
    if (leaf.bound < best) return;
    const double offset = std::hypot(leaf.x - half_x, leaf.y - half_y) + std::abs(leaf.angle);
    if (leaf.bound == best && offset >= best_offset) return;
    best = leaf.bound;
    best_offset = offset;
    best_a = leaf.angle;
    best_x = leaf.x;
    best_y = leaf.y;
  };
  // A good score early prunes most of the tree: climb from the guess (where odometry's constant
  // velocity guess and a loop's estimate usually lie close) before branching.
  {
    Block here = bound_of(0, 0, half_x, half_y);
    consider(here);
    for (int step = 0; step < 32; ++step) {
      Block up = here;
      for (int da = -1; da <= 1; ++da)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int a = here.angle + da, x = here.x + dx, y = here.y + dy;
            if ((da == 0 && dx == 0 && dy == 0) || std::abs(a) > angles || x < 0 || y < 0 ||
                x >= span_x || y >= span_y)
              continue;
            const Block b = bound_of(a, 0, x, y);
            consider(b);
            if (b.bound > up.bound) up = b;
          }
      if (up.bound == here.bound) break;  // no neighbour scores higher
      here = up;
    }
  }
  const auto descend = [&](const auto& self, const Block& block) -> void {
    if (block.level == 0) {
      consider(block);
      return;
    }
    const int side = kSides[static_cast<std::size_t>(block.level - 1)];
    std::array<Block, kBranch * kBranch> next;
    std::size_t count = 0;
    for (int dy = 0; dy < kBranch; ++dy)
      for (int dx = 0; dx < kBranch; ++dx) {
        const int x = block.x + dx * side, y = block.y + dy * side;
        if (x < span_x && y < span_y) next[count++] = bound_of(block.angle, block.level - 1, x, y);
      }
    std::sort(next.begin(), next.begin() + static_cast<std::ptrdiff_t>(count), higher_bound);
    for (std::size_t i = 0; i < count; ++i) {
      if (next[i].bound < best) break;
      self(self, next[i]);
    }
  };
  for (const Block& block : blocks) {
    if (block.bound < best) break;
    descend(descend, block);
  }
  if (!std::isfinite(best_offset)) return match;  // nothing reached the minimum score
  match.found = true;
  match.score = best / static_cast<double>(points.size());
  match.pose = space.pose(best_a, best_x, best_y);
  return match;
}

}  // namespace

CorrelativeMatch correlative_match(const Scan2D& current, const Scan2D& reference,
                                   const Pose2& initial, double window, double angle_window,
                                   double resolution, double fill_gap, double min_score) {
  check_window(window, angle_window, resolution);
  check_min_score(min_score);
  return best_in(
      search_space(current, reference, initial, window, angle_window, resolution, fill_gap),
      initial, min_score);
}

CorrelativeMatch correlative_match(const Scan2D& current, const CorrelativeGrid& reference,
                                   const Pose2& initial, double window, double angle_window,
                                   double min_score) {
  return correlative_match(current, reference, initial, Vec2::Constant(window), angle_window,
                           min_score);
}

CorrelativeMatch correlative_match(const Scan2D& current, const CorrelativeGrid& reference,
                                   const Pose2& initial, const Eigen::Vector2d& window,
                                   double angle_window, double min_score) {
  check_window(std::min(window.x(), window.y()), angle_window, reference.resolution());
  check_min_score(min_score);
  return best_in(search_space(current, reference, initial, window, angle_window), initial,
                 min_score);
}

namespace {

void check_margin(double margin) {
  if (!(margin >= 0.0)) throw Error("correlative search: the margin must not be negative");
}

/// correlative_spread over a prepared search space.
CorrelativeSpread spread_in(const SearchSpace& space, const Pose2& at, double margin,
                            const std::optional<Eigen::Vector2d>& toward) {
  CorrelativeSpread spread;
  spread.nearest = at;
  if (space.cells.empty()) return spread;
  // Each translation's best rotation. Blocks of 4 x 4 translations are bounded by the grid's first
  // max-filtered level and looked at best first; once a block's bound falls below the best found
  // less the margin, no translation in it or in any later block can count.
  const double points = static_cast<double>(space.points.size());
  const float allowance = static_cast<float>(margin * points);
  constexpr int kLevel = 1, kSide = kSides[kLevel];
  std::vector<Block> blocks;
  for (int a = -space.angles; a <= space.angles; ++a)
    for (int y = 0; y < space.span_y; y += kSide)
      for (int x = 0; x < space.span_x; x += kSide)
        blocks.push_back({space.score(a, kLevel, x, y), a, kLevel, x, y});
  std::sort(blocks.begin(), blocks.end(), higher_bound);
  const auto cells = static_cast<std::size_t>(space.span_x * space.span_y);
  std::vector<float> best_of(cells, 0.0f);
  std::vector<int> best_angle(cells, 0);
  float best = 0.0f;
  for (const Block& block : blocks) {
    if (block.bound < best - allowance) break;
    for (int y = block.y; y < std::min(block.y + kSide, space.span_y); ++y)
      for (int x = block.x; x < std::min(block.x + kSide, space.span_x); ++x) {
        const auto i = static_cast<std::size_t>(y * space.span_x + x);
        const float score = space.score(block.angle, 0, x, y);
        if (score > best_of[i]) {
          best_of[i] = score;
          best_angle[i] = block.angle;
        }
        best = std::max(best, score);
      }
  }
  spread.best_score = best / points;
  const float threshold = best - allowance;
  const double r = space.grid().resolution;
  double nearest = std::numeric_limits<double>::infinity();
  for (int y = 0; y < space.span_y; ++y)
    for (int x = 0; x < space.span_x; ++x) {
      const auto i = static_cast<std::size_t>(y * space.span_x + x);
      if (best_of[i] < threshold) continue;
      const Eigen::Vector2d offset((x - space.half_x) * r, (y - space.half_y) * r);
      spread.second_moment += offset * offset.transpose();
      ++spread.poses;
      if (toward) {
        const double d = (at.translation() + offset - *toward).squaredNorm();
        if (d < nearest) {
          nearest = d;
          spread.nearest = space.pose(best_angle[i], x, y);
        }
      }
    }
  if (spread.poses > 0) spread.second_moment /= static_cast<double>(spread.poses);
  return spread;
}

}  // namespace

CorrelativeSpread correlative_spread(const Scan2D& current, const Scan2D& reference,
                                     const Pose2& at, double window, double angle_window,
                                     double resolution, double fill_gap, double margin,
                                     const std::optional<Eigen::Vector2d>& toward) {
  check_window(window, angle_window, resolution);
  check_margin(margin);
  return spread_in(search_space(current, reference, at, window, angle_window, resolution, fill_gap),
                   at, margin, toward);
}

CorrelativeSpread correlative_spread(const Scan2D& current, const CorrelativeGrid& reference,
                                     const Pose2& at, double window, double angle_window,
                                     double margin, const std::optional<Eigen::Vector2d>& toward) {
  check_window(window, angle_window, reference.resolution());
  check_margin(margin);
  return spread_in(search_space(current, reference, at, Vec2::Constant(window), angle_window), at,
                   margin, toward);
}

SpreadAxis widest_spread(const CorrelativeSpread& spread) {
  SpreadAxis axis;
  if (spread.poses == 0 || !spread.second_moment.allFinite()) return axis;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(spread.second_moment);
  axis.direction = eigen.eigenvectors().col(1);
  axis.rms = std::sqrt(std::max(eigen.eigenvalues()(1), 0.0));
  return axis;
}

}  // namespace scanmatch
