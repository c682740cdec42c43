#include "scanmatch/registration/planar/correlative_search.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "scanmatch/core/error.hpp"

namespace scanmatch {
namespace {

using Vec2 = Eigen::Vector2d;

constexpr int kBlock = 8;  ///< translations per block side in the coarse level
constexpr std::int64_t kMaxCells = 16'000'000;

struct LikelihoodGrid {
  double resolution = 0.05;
  Vec2 origin = Vec2::Zero();  ///< world position of cell (0, 0)'s corner
  int width = 0, height = 0;
  std::vector<float> fine, block_max;  ///< block_max(x, y) = max of fine over [x, x+B) x [y, y+B)

  float at(const std::vector<float>& g, int x, int y) const {
    if (x < 0 || y < 0 || x >= width || y >= height) return 0.0f;
    return g[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
             static_cast<std::size_t>(x)];
  }
};

/// The grid spans the reference points only: a current point landing elsewhere scores nothing.
/// Below them it reaches one block further, so that block_max bounds the blocks that start
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
    return (size.x() / r + kBlock + 6) * (size.y() / r + kBlock + 6);
  };
  while (cells(resolution) > static_cast<double>(kMaxCells)) resolution *= 2;
  low -= Vec2::Constant((kBlock + 3) * resolution);
  high += Vec2::Constant(3 * resolution);
  const Vec2 size = high - low;
  g.resolution = resolution;
  g.origin = low;
  g.width = static_cast<int>(std::ceil(size.x() / resolution)) + 1;
  g.height = static_cast<int>(std::ceil(size.y() / resolution)) + 1;
  g.fine.assign(static_cast<std::size_t>(g.width) * static_cast<std::size_t>(g.height), 0.0f);
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
        float& cell = g.fine[static_cast<std::size_t>(y) * static_cast<std::size_t>(g.width) +
                             static_cast<std::size_t>(x)];
        cell = std::max(cell, kernel[dy + radius][dx + radius]);
      }
  }
  // Separable sliding maximum over kBlock cells towards +x, then +y.
  std::vector<float> rows(g.fine.size());
  for (int y = 0; y < g.height; ++y)
    for (int x = 0; x < g.width; ++x) {
      float m = 0.0f;
      for (int k = 0; k < kBlock && x + k < g.width; ++k) m = std::max(m, g.at(g.fine, x + k, y));
      rows[static_cast<std::size_t>(y) * static_cast<std::size_t>(g.width) +
           static_cast<std::size_t>(x)] = m;
    }
  g.block_max.assign(g.fine.size(), 0.0f);
  for (int y = 0; y < g.height; ++y)
    for (int x = 0; x < g.width; ++x) {
      float m = 0.0f;
      for (int k = 0; k < kBlock && y + k < g.height; ++k) m = std::max(m, g.at(rows, x, y + k));
      g.block_max[static_cast<std::size_t>(y) * static_cast<std::size_t>(g.width) +
                  static_cast<std::size_t>(x)] = m;
    }
  return g;
}

/// The current scan thinned to one point per cell: the score counts surface, not point density.
std::vector<Vec2> thinned(const std::vector<Vec2>& points, double cell) {
  std::vector<std::pair<std::int64_t, std::size_t>> keys;
  keys.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::int64_t x = static_cast<std::int64_t>(std::floor(points[i].x() / cell));
    const std::int64_t y = static_cast<std::int64_t>(std::floor(points[i].y() / cell));
    keys.push_back({x * 1'000'003 + y, i});
  }
  std::sort(keys.begin(), keys.end());
  std::vector<Vec2> out;
  for (std::size_t k = 0; k < keys.size(); ++k)
    if (k == 0 || keys[k].first != keys[k - 1].first) out.push_back(points[keys[k].second]);
  return out;
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
  if (!(window > 0.0) || !(angle_window >= 0.0) || !(resolution > 0.0))
    throw Error("correlative search: window and resolution must be positive");
  if (current.points.empty() || reference.points.empty()) return initial;
  const std::vector<Vec2> points = thinned(current.points, 2 * resolution);

  // The grid covers where the current scan can land: its footprint under the initial guess,
  // grown by the window and the rotation's sweep.
  double max_range = 0.0;
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
  const double step_range = *percentile;
  Vec2 low = initial.translation(), high = initial.translation();
  for (const Vec2& p : points) {
    const Vec2 q = initial * p;
    low = low.cwiseMin(q);
    high = high.cwiseMax(q);
  }
  const double margin = window + std::min(max_range, max_range * angle_window) + 4 * resolution;
  low -= Vec2::Constant(margin);
  high += Vec2::Constant(margin);
  std::vector<Vec2> useful;
  for (const Vec2& q : filled_surfaces(reference, fill_gap, resolution))
    if ((q.array() >= low.array()).all() && (q.array() <= high.array()).all()) useful.push_back(q);
  if (useful.empty()) return initial;
  const LikelihoodGrid g = make_grid(useful, resolution);
  const double r = g.resolution;

  // Angular step: a point at `step_range` moves by about one cell.
  const double angle_step =
      std::clamp(r / std::max(step_range, 1e-3), 0.1 * M_PI / 180, 1.0 * M_PI / 180);
  const int angles = static_cast<int>(std::ceil(angle_window / angle_step));
  const int half = static_cast<int>(std::ceil(window / r));  // translations -half..half cells
  const double theta0 = pose2_angle(initial);

  struct Candidate {
    float bound;
    int angle, bx, by;  ///< block corner, in translation cells relative to -half
  };
  std::vector<Candidate> candidates;
  std::vector<std::vector<std::pair<int, int>>> cells(static_cast<std::size_t>(2 * angles + 1));
  const int span = 2 * half + 1;
  for (int a = -angles; a <= angles; ++a) {
    const Pose2 T =
        pose2(initial.translation().x(), initial.translation().y(), theta0 + a * angle_step);
    auto& c = cells[static_cast<std::size_t>(a + angles)];
    c.reserve(points.size());
    for (const Vec2& p : points) {
      const Vec2 q = (T * p - g.origin) / r;
      c.push_back(
          {static_cast<int>(std::floor(q.x())) - half, static_cast<int>(std::floor(q.y())) - half});
    }
    for (int by = 0; by < span; by += kBlock)
      for (int bx = 0; bx < span; bx += kBlock) {
        float bound = 0.0f;
        for (const auto& [x, y] : c) bound += g.at(g.block_max, x + bx, y + by);
        candidates.push_back({bound, a, bx, by});
      }
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& a, const Candidate& b) { return a.bound > b.bound; });
  // Exact at the fine level: a block whose bound cannot beat the best score so far is skipped,
  // and so is everything after it (sorted). Ties go to the translation nearest the guess.
  float best = -1.0f;
  int best_a = 0, best_x = half, best_y = half;
  double best_offset = std::numeric_limits<double>::infinity();
  for (const Candidate& cand : candidates) {
    if (cand.bound < best) break;
    const auto& c = cells[static_cast<std::size_t>(cand.angle + angles)];
    for (int ty = cand.by; ty < std::min(cand.by + kBlock, span); ++ty)
      for (int tx = cand.bx; tx < std::min(cand.bx + kBlock, span); ++tx) {
        float score = 0.0f;
        for (const auto& [x, y] : c) score += g.at(g.fine, x + tx, y + ty);
        if (score < best) continue;
        const double offset = std::hypot(tx - half, ty - half) + std::abs(cand.angle);
        if (score > best || offset < best_offset) {
          best = score;
          best_offset = offset;
          best_a = cand.angle;
          best_x = tx;
          best_y = ty;
        }
      }
  }
  return pose2(initial.translation().x() + (best_x - half) * r,
               initial.translation().y() + (best_y - half) * r, theta0 + best_a * angle_step);
}

}  // namespace scanmatch
