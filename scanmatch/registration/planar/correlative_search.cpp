#include "scanmatch/registration/planar/correlative_search.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <tuple>
#include <utility>
#include <vector>

#include "scanmatch/core/error.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace scanmatch {
namespace {

using Vec2 = Eigen::Vector2d;

/// The branch and bound's levels: each level's cell bounds the kBranch x kBranch cells of the
/// level below it, so level k's blocks have side kSides[k] = kBranch^k.
constexpr int kBranch = 4;
constexpr int kLevels = 4;
constexpr std::array<int, kLevels> kSides = [] {
  std::array<int, kLevels> sides{};
  for (int k = 0, side = 1; k < kLevels; ++k, side *= kBranch)
    sides[static_cast<std::size_t>(k)] = side;
  return sides;
}();
constexpr int kTopSide = kSides[kLevels - 1];
static_assert(kTopSide == 64);
/// Cells of one level beyond which the grid coarsens.
constexpr std::int64_t kMaxCellsPerLevel = 4'000'000;

/// The smoothing kernel: a Gaussian of sigma = one cell around each reference point, out to
/// kRadius cells. Its values are few (one per squared distance), so a cell holds a byte, the code
/// of its value v: ceil(255 v), 0 off every surface. The codes grow with the values, so the maximum
/// of codes is the code of the maximum. A quarter of the floats' memory (the searches' reads miss
/// the cache less); a pose's score sums the floats the codes stand for, in the points' order (the
/// same sums to the bit), while a block's bound sums the codes themselves as integers (four lanes
/// at once), which bound those floats from above.
constexpr int kRadius = 2;
using Code = std::uint8_t;
constexpr int kCodeScale = 255;

struct LikelihoodGrid {
  double resolution = 0.05;
  Vec2 origin = Vec2::Zero();  ///< world position of cell (0, 0)'s corner
  int width = 0, height = 0;
  std::array<float, kCodeScale + 1> likelihood{};  ///< by code
  /// Level k's codes start at k * cells(): level 0 is the smoothed likelihood; level k's (x, y) is
  /// the maximum of level 0 over the square of side kBranch^k from (x, y) towards +x and +y. A
  /// few bytes more at the end, so that 16 can be read from any cell.
  std::vector<Code> codes;

  std::size_t cells() const {
    return static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  }
  const Code* level(int k) const { return codes.data() + static_cast<std::size_t>(k) * cells(); }
  Code code(int k, int x, int y) const {
    if (x < 0 || y < 0 || x >= width || y >= height) return 0;
    return level(k)[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
                    static_cast<std::size_t>(x)];
  }
  float at(int k, int x, int y) const { return likelihood[code(k, x, y)]; }
};

/// The grid spans the reference points only: a current point landing elsewhere scores nothing.
/// Below them it reaches one top block further, so that the levels bound the blocks that start
/// outside (`g.at` is zero off the grid). Coarser cells where the area is huge, so memory stays
/// bounded. With `older` (surfaces of earlier scans, in the reference's frame) a cell holds the
/// mean of the two sets' likelihoods, each code standing for code / 255.
LikelihoodGrid make_grid(const std::vector<Vec2>& reference, double resolution,
                         const std::vector<Vec2>& older = {}) {
  LikelihoodGrid g;
  Vec2 low = reference.front(), high = reference.front();
  for (const std::vector<Vec2>* points : {&reference, &older})
    for (const Vec2& p : *points) {
      low = low.cwiseMin(p);
      high = high.cwiseMax(p);
    }
  const auto cells = [&](double r) {
    const Vec2 size = high - low;
    return (size.x() / r + kTopSide + 6) * (size.y() / r + kTopSide + 6);
  };
  while (cells(resolution) > static_cast<double>(kMaxCellsPerLevel)) resolution *= 2;
  low -= Vec2::Constant((kTopSide + 3) * resolution);
  high += Vec2::Constant(3 * resolution);
  const Vec2 size = high - low;
  g.resolution = resolution;
  g.origin = low;
  g.width = static_cast<int>(std::ceil(size.x() / resolution)) + 1;
  g.height = static_cast<int>(std::ceil(size.y() / resolution)) + 1;
  const std::size_t n = g.cells();
  const std::size_t width = static_cast<std::size_t>(g.width);
  g.codes.assign(n * kLevels + 16, 0);
  Code* fine = g.codes.data();
  // Each offset's code; the float it stands for (exactly: 255 v is exact in a double).
  Code kernel[2 * kRadius + 1][2 * kRadius + 1];
  for (int dy = -kRadius; dy <= kRadius; ++dy)
    for (int dx = -kRadius; dx <= kRadius; ++dx) {
      const float value = static_cast<float>(std::exp(-0.5 * (dx * dx + dy * dy)));
      const auto code = static_cast<Code>(std::ceil(kCodeScale * static_cast<double>(value)));
      kernel[dy + kRadius][dx + kRadius] = code;
      g.likelihood[code] = value;
    }
  const auto stamp = [&](const std::vector<Vec2>& points, Code* layer) {
    for (const Vec2& p : points) {
      const int cx = static_cast<int>(std::floor((p.x() - low.x()) / resolution));
      const int cy = static_cast<int>(std::floor((p.y() - low.y()) / resolution));
      for (int dy = -kRadius; dy <= kRadius; ++dy)
        for (int dx = -kRadius; dx <= kRadius; ++dx) {
          const int x = cx + dx, y = cy + dy;
          if (x < 0 || y < 0 || x >= g.width || y >= g.height) continue;
          Code& cell = layer[static_cast<std::size_t>(y) * width + static_cast<std::size_t>(x)];
          cell = std::max(cell, kernel[dy + kRadius][dx + kRadius]);
        }
    }
  };
  stamp(reference, fine);
  if (!older.empty()) {
    std::vector<Code> earlier(n, 0);
    stamp(older, earlier.data());
    for (std::size_t i = 0; i < n; ++i)
      fine[i] = static_cast<Code>((fine[i] + earlier[i] + 1) / 2);  // the mean, rounded up
    for (int code = 0; code <= kCodeScale; ++code)
      g.likelihood[static_cast<std::size_t>(code)] = static_cast<float>(code) / kCodeScale;
  }
  // Each level from the one below: the maximum of kBranch cells `stride` apart along +x, then, in
  // place, along +y (row y reads only rows after it, not yet overwritten). Off the grid counts as
  // zero; written branch-free over whole rows so that it vectorizes.
  static_assert(kBranch == 4, "four cells a pass");
  const std::size_t height = static_cast<std::size_t>(g.height);
  std::size_t stride = 1;
  for (std::size_t level = 1; level < kLevels; ++level, stride *= kBranch) {
    const Code* below = g.codes.data() + (level - 1) * n;
    Code* out = g.codes.data() + level * n;
    const std::size_t reach = std::min((kBranch - 1) * stride, width);
    for (std::size_t y = 0; y < height; ++y) {
      const Code* in = below + y * width;
      Code* row = out + y * width;
      // Where all kBranch cells lie on the row in one pass; towards its end, fewer.
      for (std::size_t x = 0; x + reach < width; ++x)
        row[x] = std::max(std::max(in[x], in[x + stride]),
                          std::max(in[x + 2 * stride], in[x + 3 * stride]));
      for (std::size_t x = width - reach; x < width; ++x) {
        Code m = in[x];
        for (std::size_t k = 1; k < kBranch && x + k * stride < width; ++k)
          m = std::max(m, in[x + k * stride]);
        row[x] = m;
      }
    }
    for (std::size_t y = 0; y < height; ++y) {
      Code* row = out + y * width;
      if (y + 3 * stride < height) {
        const Code *a = row + stride * width, *b = row + 2 * stride * width,
                   *c = row + 3 * stride * width;
        for (std::size_t x = 0; x < width; ++x)
          row[x] = std::max(std::max(row[x], a[x]), std::max(b[x], c[x]));
        continue;
      }
      for (std::size_t k = 1; k < kBranch; ++k) {
        const std::size_t other = y + k * stride;
        if (other >= height) break;
        const Code* in = out + other * width;
        for (std::size_t x = 0; x < width; ++x) row[x] = std::max(row[x], in[x]);
      }
    }
  }
  static_assert(kLevels == 4 && kBranch == 4, "the bounds read levels 1 and 2 as 4 x 4 children");
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

/// The scores of a block's children, row by row.
using ChildScores = std::array<float, 16>;

/// A block of translations (corner x, y in cells from the window's -half, side kSides[level]) at
/// one rotation, with the upper bound of their scores at that level.
struct Block {
  float bound;
  int angle, level, x, y;
};
bool higher_bound(const Block& a, const Block& b) {
  return a.bound > b.bound;
}

/// A point's cell on the grid, (x, y).
using Cell = std::pair<int, int>;

/// The current scan's thinned points about an initial guess on a reference's likelihood grid, with
/// the cells they fall in under each rotation the searches looked at (kept for the next search
/// about the same guess). Rotation a turns the guess by a angular steps.
class ScanOnGrid {
 public:
  ScanOnGrid(std::vector<Vec2> points, double step_range,
             std::shared_ptr<const LikelihoodGrid> grid, const Pose2& initial)
      : points_(std::move(points)), grid_(std::move(grid)), initial_(initial) {
    // Angular step: a point at `step_range` moves by about one cell.
    angle_step_ = std::clamp(grid_->resolution / std::max(step_range, 1e-3), 0.1 * M_PI / 180,
                             1.0 * M_PI / 180);
  }
  const std::vector<Vec2>& points() const { return points_; }
  const LikelihoodGrid& grid() const { return *grid_; }
  const Pose2& initial() const { return initial_; }
  double angle_step() const { return angle_step_; }
  /// The rotations -angles..angles steps are available from here on.
  void prepare(int angles);
  /// The points' grid cells under rotation `angle` (prepared), at the guess's translation.
  const std::vector<Cell>& cells(int angle) const {
    return cells_[static_cast<std::size_t>(angle + angles_)];
  }

 private:
  std::vector<Vec2> points_;
  std::shared_ptr<const LikelihoodGrid> grid_;
  Pose2 initial_ = Pose2::Identity();
  double angle_step_ = 0.0;
  int angles_ = -1;
  std::vector<std::vector<Cell>> cells_;  ///< by rotation + angles_
};

void ScanOnGrid::prepare(int angles) {
  if (angles <= angles_) return;
  std::vector<std::vector<Cell>> cells(static_cast<std::size_t>(2 * angles + 1));
  for (int a = -angles_; a <= angles_; ++a)
    cells[static_cast<std::size_t>(a + angles)] =
        std::move(cells_[static_cast<std::size_t>(a + angles_)]);
  // floor() through a shift into positive numbers (a plain conversion truncates): far cheaper
  // than std::floor, exact within 2^20 cells of the grid; farther (a wild point) is clamped, still
  // off the grid, where a conversion would overflow.
  constexpr double kShift = 1 << 20;
  const auto cell = [&](double v) {
    return static_cast<int>(std::clamp(v, -kShift, kShift) + kShift) - (1 << 20);
  };
  const LikelihoodGrid& g = *grid_;
  const double r = g.resolution;
  const Vec2 start = (initial_.translation() - g.origin) / r;
  for (int a = -angles; a <= angles; ++a) {
    if (std::abs(a) <= angles_) continue;  // kept from before
    const double theta = pose2_angle(initial_) + a * angle_step_;
    const double c = std::cos(theta) / r, s = std::sin(theta) / r;
    auto& out = cells[static_cast<std::size_t>(a + angles)];
    out.reserve(points_.size());
    for (const Vec2& p : points_)
      out.push_back(
          {cell(c * p.x() - s * p.y() + start.x()), cell(s * p.x() + c * p.y() + start.y())});
  }
  cells_ = std::move(cells);
  angles_ = angles;
}

/// What a search over a window scores: rotations -angles..angles steps and translations
/// -half..half cells about the guess; window cell (x, y) (0..span - 1) is translation
/// (x - half_x, y - half_y). Without `scan` nothing can be scored.
struct SearchSpace {
  ScanOnGrid* scan = nullptr;
  int angles = 0;
  int half_x = 0, half_y = 0;
  int span_x = 0, span_y = 0;  ///< 2 * half + 1

  SearchSpace() = default;
  SearchSpace(ScanOnGrid& on_grid, const Vec2& window, double angle_window) : scan(&on_grid) {
    const double r = on_grid.grid().resolution;
    angles = static_cast<int>(std::ceil(angle_window / on_grid.angle_step()));
    half_x = static_cast<int>(std::ceil(window.x() / r));
    half_y = static_cast<int>(std::ceil(window.y() / r));
    span_x = 2 * half_x + 1;
    span_y = 2 * half_y + 1;
    on_grid.prepare(angles);
  }
  bool empty() const { return scan == nullptr; }
  std::size_t points() const { return scan->points().size(); }
  const LikelihoodGrid& grid() const { return scan->grid(); }

  /// At level 0, the pose's score at window cell (x, y): the sum over the points of the
  /// likelihood. Above, a bound of the scores of the block from there (its side: the level's).
  float score(int angle, int level, int x, int y) const {
    const LikelihoodGrid& g = grid();
    const int shift_x = x - half_x, shift_y = y - half_y;
    if (level == 0) {
      float sum = 0.0f;
      for (const auto& [cx, cy] : scan->cells(angle)) sum += g.at(0, cx + shift_x, cy + shift_y);
      return sum;
    }
    std::uint32_t sum = 0;
    for (const auto& [cx, cy] : scan->cells(angle))
      sum += g.code(level, cx + shift_x, cy + shift_y);
    return bound(sum);
  }
  /// A sum of codes as a bound of the scores' floats: above the exact sum of the values they
  /// stand for by the float rounding of a sum of points() terms and of the conversion.
  float bound(std::uint32_t codes) const {
    const double scale =
        (1.0 + static_cast<double>(points() + 4) * std::ldexp(1.0, -23)) / kCodeScale;
    return static_cast<float>(codes * scale);
  }
  /// The scores of a block's kBranch x kBranch children at `level` (their corners `Side` cells
  /// apart from window cell (x, y), row by row) in one pass over the points: each child's sum adds
  /// the same floats in the same order as score() does, so the scores are the same to the bit.
  template <int Side, int Count = kBranch>
  void child_scores(int angle, int level, int x, int y, ChildScores& out) const;
  /// The bounds of the kBranch x kBranch children at `Level` (1: a level-2 block's, corners 4
  /// cells apart; 2: a top block's, 16 apart), as score() gives them, from their codes summed as
  /// integers (level 1's four a row at once with SSE2).
  template <int Level>
  void child_bounds(int angle, int x, int y, ChildScores& out) const;
  /// The scores (level 1: of the poses) or bounds of the children of the block at `level` (1 to
  /// kLevels - 1) with its corner at (x, y), row by row.
  void children(int angle, int level, int x, int y, ChildScores& out) const {
    if (level == 1) return child_scores<1>(angle, 0, x, y, out);
    if (level == 2) return child_bounds<1>(angle, x, y, out);
    child_bounds<2>(angle, x, y, out);
  }
  Pose2 pose(int angle, int x, int y) const {
    const Pose2& initial = scan->initial();
    const double r = grid().resolution;
    return pose2(initial.translation().x() + (x - half_x) * r,
                 initial.translation().y() + (y - half_y) * r,
                 pose2_angle(initial) + angle * scan->angle_step());
  }
};

template <int Side, int Count>
void SearchSpace::child_scores(int angle, int level, int x, int y, ChildScores& out) const {
  static_assert(Count * Count <= std::tuple_size_v<ChildScores>);
  constexpr int kReach = (Count - 1) * Side;  // from the first child's cell to the last's
  const LikelihoodGrid& g = grid();
  const Code* data = g.level(level);
  const std::array<float, kCodeScale + 1>& likelihood = g.likelihood;
  const int width = g.width, height = g.height;
  const std::size_t row_step = static_cast<std::size_t>(Side) * static_cast<std::size_t>(width);
  const int shift_x = x - half_x, shift_y = y - half_y;
  ChildScores sum{};
  for (const auto& [cx, cy] : scan->cells(angle)) {
    const int gx = cx + shift_x, gy = cy + shift_y;
    if (gx >= 0 && gy >= 0 && gx + kReach < width && gy + kReach < height) {
      const Code* row = data + static_cast<std::size_t>(gy) * static_cast<std::size_t>(width) +
                        static_cast<std::size_t>(gx);
      for (int dy = 0; dy < Count; ++dy, row += row_step)
        for (int dx = 0; dx < Count; ++dx) sum[dy * Count + dx] += likelihood[row[dx * Side]];
    } else if (gx + kReach >= 0 && gy + kReach >= 0 && gx < width && gy < height) {
      // Partly on the grid; off it adds nothing (a zero leaves a float sum as it was).
      for (int dy = 0; dy < Count; ++dy)
        for (int dx = 0; dx < Count; ++dx)
          sum[dy * Count + dx] += g.at(level, gx + dx * Side, gy + dy * Side);
    }
  }
  out = sum;
}

// Sums of the codes of 4 x 4 children, a row of four per lane group: with SSE2 four at once.
#if defined(__SSE2__)
struct RowSums {
  __m128i rows[kBranch] = {_mm_setzero_si128(), _mm_setzero_si128(), _mm_setzero_si128(),
                           _mm_setzero_si128()};
  /// Adds lane k of `codes` (4 x 32 bits, codes in the low bytes) to child (k, dy).
  void add(int dy, __m128i codes) { rows[dy] = _mm_add_epi32(rows[dy], codes); }
  std::array<std::uint32_t, 16> sums() const {
    std::array<std::uint32_t, 16> out;
    for (std::size_t dy = 0; dy < kBranch; ++dy)
      _mm_storeu_si128(reinterpret_cast<__m128i*>(out.data() + 4 * dy), rows[dy]);
    return out;
  }
};
#endif

template <int Level>
void SearchSpace::child_bounds(int angle, int x, int y, ChildScores& out) const {
  constexpr int kSide = kSides[Level], kReach = (kBranch - 1) * kSide;
  // One 16-byte load reads a row's four children where they lie 4 bytes apart (level 1).
#if defined(__SSE2__)
  constexpr bool kVector = kSide == 4;
#else
  constexpr bool kVector = false;
#endif
  const LikelihoodGrid& g = grid();
  const Code* data = g.level(Level);
  const int width = g.width, height = g.height;
  const std::size_t row_step = static_cast<std::size_t>(kSide) * static_cast<std::size_t>(width);
  const int shift_x = x - half_x, shift_y = y - half_y;
  std::array<std::uint32_t, 16> sum{};
#if defined(__SSE2__)
  RowSums rows;
  const __m128i low_bytes = _mm_set1_epi32(0xFF);
#endif
  for (const auto& [cx, cy] : scan->cells(angle)) {
    const int gx = cx + shift_x, gy = cy + shift_y;
    if (gx >= 0 && gy >= 0 && gx + kReach < width && gy + kReach < height) {
      const Code* row = data + static_cast<std::size_t>(gy) * static_cast<std::size_t>(width) +
                        static_cast<std::size_t>(gx);
      for (int dy = 0; dy < kBranch; ++dy, row += row_step) {
        if constexpr (kVector) {
#if defined(__SSE2__)
          // 16 bytes from the first child's cell: each 32-bit lane's low byte is a child's.
          rows.add(
              dy, _mm_and_si128(_mm_loadu_si128(reinterpret_cast<const __m128i*>(row)), low_bytes));
#endif
        } else {
          for (int dx = 0; dx < kBranch; ++dx) sum[dy * kBranch + dx] += row[dx * kSide];
        }
      }
    } else if (gx + kReach >= 0 && gy + kReach >= 0 && gx < width && gy < height) {
      for (int dy = 0; dy < kBranch; ++dy)
        for (int dx = 0; dx < kBranch; ++dx)
          sum[dy * kBranch + dx] += g.code(Level, gx + dx * kSide, gy + dy * kSide);
    }
  }
#if defined(__SSE2__)
  if constexpr (kVector) {
    const std::array<std::uint32_t, 16> lanes = rows.sums();
    for (std::size_t i = 0; i < sum.size(); ++i) sum[i] += lanes[i];
  }
#endif
  for (std::size_t i = 0; i < sum.size(); ++i) out[i] = bound(sum[i]);
}

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

/// The current scan about `initial` onto `reference`'s filled surfaces where it can land (its
/// footprint under `initial`, grown by the window and the rotation's sweep); none when nothing can
/// be scored.
std::optional<ScanOnGrid> scan_on_grid(const Scan2D& current, const Scan2D& reference,
                                       const Pose2& initial, double window, double angle_window,
                                       double resolution, double fill_gap) {
  if (current.points.empty() || reference.points.empty()) return std::nullopt;
  SearchPoints points = search_points(current, resolution);
  if (points.points.empty()) return std::nullopt;
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
  if (useful.empty()) return std::nullopt;
  return ScanOnGrid(std::move(points.points), points.step_range,
                    std::make_shared<LikelihoodGrid>(make_grid(useful, resolution)), initial);
}

}  // namespace

struct CorrelativeGrid::Impl {
  std::shared_ptr<const LikelihoodGrid> grid;
};

CorrelativeGrid::CorrelativeGrid(const Scan2D& reference, double resolution, double fill_gap)
    : CorrelativeGrid(filled_surfaces(reference, fill_gap, resolution), {}, resolution) {}

CorrelativeGrid::CorrelativeGrid(const std::vector<Vec2>& newest, const std::vector<Vec2>& older,
                                 double resolution)
    : requested_resolution_(resolution) {
  if (!(resolution > 0.0)) throw Error("correlative search: resolution must be positive");
  const auto finite = [](const std::vector<Vec2>& points) {
    std::vector<Vec2> out;
    out.reserve(points.size());
    for (const Vec2& q : points)
      if (q.allFinite()) out.push_back(q);
    return out;
  };
  const std::vector<Vec2> surfaces = finite(newest);
  if (surfaces.empty()) return;
  auto impl = std::make_shared<Impl>();
  impl->grid = std::make_shared<LikelihoodGrid>(make_grid(surfaces, resolution, finite(older)));
  impl_ = std::move(impl);
}

namespace {

std::optional<ScanOnGrid> scan_on_grid(const Scan2D& current, const CorrelativeGrid& reference,
                                       const Pose2& initial) {
  if (current.points.empty() || reference.empty()) return std::nullopt;
  SearchPoints points = search_points(current, reference.resolution());
  if (points.points.empty()) return std::nullopt;
  return ScanOnGrid(std::move(points.points), points.step_range, reference.impl().grid, initial);
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

/// A window an earlier search about the same guess looked over, and what it found there: the best
/// pose (as translation and rotation steps from the guess) with its score and distance from the
/// guess, or, when not `found`, that nothing there reached `floor`.
struct SearchedWindow {
  int angles = 0, half_x = 0, half_y = 0;
  float floor = 0.0f;
  bool found = false;
  float score = 0.0f;
  double offset = 0.0;
  int angle = 0, x = 0, y = 0;
};

/// correlative_match over a prepared search space. Windows searched before (`searched`) that lie
/// within this one are not looked at again: their best starts as the best so far, and any block
/// inside one of them can hold no better pose (a tie only nearer the guess, which that search
/// would have kept). `found` records what this search finds.
CorrelativeMatch best_in(const SearchSpace& space, const Pose2& initial, double min_score,
                         const std::vector<SearchedWindow>& searched = {},
                         SearchedWindow* found = nullptr) {
  CorrelativeMatch match;
  match.pose = initial;
  if (space.empty()) return match;
  const int angles = space.angles, half_x = space.half_x, half_y = space.half_y,
            span_x = space.span_x, span_y = space.span_y;
  // Below the minimum nothing counts, so the bounds prune from the start.
  const float floor = static_cast<float>(min_score * static_cast<double>(space.points()));
  float best = floor;
  int best_a = 0, best_x = half_x, best_y = half_y;
  double best_offset = std::numeric_limits<double>::infinity();
  // The earlier windows inside this one whose every pose is known: each found its best, or found
  // nothing at or above a floor no higher than this one.
  std::vector<const SearchedWindow*> known;
  for (const SearchedWindow& w : searched) {
    if (w.angles > angles || w.half_x > half_x || w.half_y > half_y) continue;
    if (!w.found && w.floor > floor) continue;
    known.push_back(&w);
    if (w.found && (w.score > best || (w.score == best && w.offset < best_offset))) {
      best = w.score;
      best_offset = w.offset;
      best_a = w.angle;
      best_x = w.x + half_x;
      best_y = w.y + half_y;
    }
  }
  // Whether all of a block's poses lie in a known window.
  const auto known_block = [&](int angle, int level, int x, int y) {
    const int side = kSides[static_cast<std::size_t>(level)];
    const int x0 = x - half_x, x1 = std::min(x + side, span_x) - 1 - half_x;
    const int y0 = y - half_y, y1 = std::min(y + side, span_y) - 1 - half_y;
    for (const SearchedWindow* w : known)
      if (std::abs(angle) <= w->angles && x0 >= -w->half_x && x1 <= w->half_x && y0 >= -w->half_y &&
          y1 <= w->half_y)
        return true;
    return false;
  };
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
  // Blocks over the cells x_low..x_high, y_low..y_high (inclusive), laid from the high end down
  // where `from_high`: a block that reached into a known window would hold its best and never be
  // pruned. Blocks may start before the window (negative corners) or end after it.
  const auto tile = [&](int a, int x_low, int x_high, bool x_from_high, int y_low, int y_high,
                        bool y_from_high) {
    if (x_low > x_high || y_low > y_high) return;
    const int x_start = x_from_high ? x_high - top_side + 1 : x_low;
    const int y_start = y_from_high ? y_high - top_side + 1 : y_low;
    for (int y = y_start; y + top_side > y_low && y <= y_high;
         y += y_from_high ? -top_side : top_side)
      for (int x = x_start; x + top_side > x_low && x <= x_high;
           x += x_from_high ? -top_side : top_side)
        if (!known_block(a, top, x, y)) blocks.push_back(bound_of(a, top, x, y));
  };
  for (int a = -angles; a <= angles; ++a) {
    // The largest known window at this rotation: the blocks tile the window around it.
    const SearchedWindow* inner = nullptr;
    for (const SearchedWindow* w : known)
      if (std::abs(a) <= w->angles &&
          (inner == nullptr || w->half_x * w->half_y > inner->half_x * inner->half_y))
        inner = w;
    if (inner == nullptr) {
      tile(a, 0, span_x - 1, false, 0, span_y - 1, false);
      continue;
    }
    const int x0 = half_x - inner->half_x, x1 = half_x + inner->half_x;
    const int y0 = half_y - inner->half_y, y1 = half_y + inner->half_y;
    tile(a, 0, x0 - 1, true, 0, span_y - 1, false);            // before it along x
    tile(a, x1 + 1, span_x - 1, false, 0, span_y - 1, false);  // after it
    tile(a, x0, x1, false, 0, y0 - 1, true);                   // before it along y
    tile(a, x0, x1, false, y1 + 1, span_y - 1, false);         // after it
  }
  std::sort(blocks.begin(), blocks.end(), higher_bound);
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
  // velocity guess and a loop's estimate usually lie close) before branching. A known window
  // holds the guess and gave its best already.
  if (known.empty()) {
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
    const int level = block.level - 1, side = kSides[static_cast<std::size_t>(level)];
    ChildScores scores;
    space.children(block.angle, block.level, block.x, block.y, scores);
    std::array<Block, kBranch * kBranch> next;
    std::size_t count = 0;
    for (int dy = 0; dy < kBranch; ++dy)
      for (int dx = 0; dx < kBranch; ++dx) {
        const int x = block.x + dx * side, y = block.y + dy * side;
        if (x + side > 0 && y + side > 0 && x < span_x && y < span_y)
          next[count++] =
              Block{scores[static_cast<std::size_t>(dy * kBranch + dx)], block.angle, level, x, y};
      }
    std::sort(next.begin(), next.begin() + static_cast<std::ptrdiff_t>(count), higher_bound);
    for (std::size_t i = 0; i < count; ++i) {
      if (next[i].bound < best) break;
      if (level > 0 && !known.empty() && known_block(next[i].angle, level, next[i].x, next[i].y))
        continue;
      self(self, next[i]);
    }
  };
  for (const Block& block : blocks) {
    if (block.bound < best) break;
    descend(descend, block);
  }
  const bool any = std::isfinite(best_offset);
  if (found != nullptr)
    *found = SearchedWindow{angles, half_x,      half_y, floor,           any,
                            best,   best_offset, best_a, best_x - half_x, best_y - half_y};
  if (!any) return match;  // nothing reached the minimum score
  match.found = true;
  match.score = best / static_cast<double>(space.points());
  match.pose = space.pose(best_a, best_x, best_y);
  return match;
}

}  // namespace

struct CorrelativeSearches::State {
  std::optional<ScanOnGrid> scan;
  Pose2 initial = Pose2::Identity();
  double resolution = 0.05;
  std::vector<SearchedWindow> searched;
};

CorrelativeSearches::CorrelativeSearches(const Scan2D& current, const CorrelativeGrid& reference,
                                         const Pose2& initial)
    : state_(std::make_unique<State>()) {
  state_->scan = scan_on_grid(current, reference, initial);
  state_->initial = initial;
  state_->resolution = reference.resolution();
}

CorrelativeSearches::~CorrelativeSearches() = default;

CorrelativeMatch CorrelativeSearches::match(const Eigen::Vector2d& window, double angle_window,
                                            double min_score) {
  check_window(std::min(window.x(), window.y()), angle_window, state_->resolution);
  check_min_score(min_score);
  if (!state_->scan) return best_in(SearchSpace(), state_->initial, min_score);
  SearchedWindow found;
  const CorrelativeMatch match = best_in(SearchSpace(*state_->scan, window, angle_window),
                                         state_->initial, min_score, state_->searched, &found);
  state_->searched.push_back(found);
  return match;
}

CorrelativeMatch correlative_match(const Scan2D& current, const Scan2D& reference,
                                   const Pose2& initial, double window, double angle_window,
                                   double resolution, double fill_gap, double min_score) {
  check_window(window, angle_window, resolution);
  check_min_score(min_score);
  std::optional<ScanOnGrid> scan =
      scan_on_grid(current, reference, initial, window, angle_window, resolution, fill_gap);
  if (!scan) return best_in(SearchSpace(), initial, min_score);
  return best_in(SearchSpace(*scan, Vec2::Constant(window), angle_window), initial, min_score);
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
  return CorrelativeSearches(current, reference, initial).match(window, angle_window, min_score);
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
  if (space.empty()) return spread;
  // Each translation's best rotation. Blocks of 4 x 4 translations are bounded by the grid's first
  // max-filtered level and looked at best first; once a block's bound falls below the best found
  // less the margin, no translation in it or in any later block can count.
  const double points = static_cast<double>(space.points());
  const float allowance = static_cast<float>(margin * points);
  constexpr int kSide = 4;
  constexpr int kLevel =
      static_cast<int>(std::find(kSides.begin(), kSides.end(), kSide) - kSides.begin());
  static_assert(kLevel == 1, "the blocks' bounds come 16 at a time, as a level-2 block's children");
  // Each rotation's blocks, row by row (the order score() would give them in, one at a time).
  const int columns = (space.span_x + kSide - 1) / kSide, rows = (space.span_y + kSide - 1) / kSide;
  std::vector<Block> blocks;
  blocks.reserve(static_cast<std::size_t>((2 * space.angles + 1) * columns * rows));
  std::vector<float> bounds(static_cast<std::size_t>(columns * rows));
  ChildScores children;
  for (int a = -space.angles; a <= space.angles; ++a) {
    for (int y = 0; y < space.span_y; y += kBranch * kSide)
      for (int x = 0; x < space.span_x; x += kBranch * kSide) {
        space.child_bounds<1>(a, x, y, children);
        for (int dy = 0; dy < kBranch && y + dy * kSide < space.span_y; ++dy)
          for (int dx = 0; dx < kBranch && x + dx * kSide < space.span_x; ++dx)
            bounds[static_cast<std::size_t>((y / kSide + dy) * columns + x / kSide + dx)] =
                children[static_cast<std::size_t>(dy * kBranch + dx)];
      }
    for (int y = 0; y < space.span_y; y += kSide)
      for (int x = 0; x < space.span_x; x += kSide)
        blocks.push_back(
            {bounds[static_cast<std::size_t>(y / kSide * columns + x / kSide)], a, kLevel, x, y});
  }
  std::sort(blocks.begin(), blocks.end(), higher_bound);
  const auto cells = static_cast<std::size_t>(space.span_x * space.span_y);
  std::vector<float> best_of(cells, 0.0f);
  std::vector<int> best_angle(cells, 0);
  float best = 0.0f;
  ChildScores scores;
  for (const Block& block : blocks) {
    if (block.bound < best - allowance) break;
    space.child_scores<1, kSide>(block.angle, 0, block.x, block.y, scores);
    for (int y = block.y; y < std::min(block.y + kSide, space.span_y); ++y)
      for (int x = block.x; x < std::min(block.x + kSide, space.span_x); ++x) {
        const auto i = static_cast<std::size_t>(y * space.span_x + x);
        const float score = scores[static_cast<std::size_t>((y - block.y) * kSide + x - block.x)];
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
  std::optional<ScanOnGrid> scan =
      scan_on_grid(current, reference, at, window, angle_window, resolution, fill_gap);
  if (!scan) return spread_in(SearchSpace(), at, margin, toward);
  return spread_in(SearchSpace(*scan, Vec2::Constant(window), angle_window), at, margin, toward);
}

CorrelativeSpread correlative_spread(const Scan2D& current, const CorrelativeGrid& reference,
                                     const Pose2& at, double window, double angle_window,
                                     double margin, const std::optional<Eigen::Vector2d>& toward) {
  check_window(window, angle_window, reference.resolution());
  check_margin(margin);
  std::optional<ScanOnGrid> scan = scan_on_grid(current, reference, at);
  if (!scan) return spread_in(SearchSpace(), at, margin, toward);
  return spread_in(SearchSpace(*scan, Vec2::Constant(window), angle_window), at, margin, toward);
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
