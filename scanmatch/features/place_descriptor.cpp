// The place descriptor: making and comparing polar grids (place_descriptor.hpp).
#include "scanmatch/features/place_descriptor.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "scanmatch/core/error.hpp"

namespace scanmatch {
namespace {

// Shift search: the sector keys rank every circular shift cheaply; the full grids are compared at
// the best few and their neighbours (the sector key is coarse, the true shift is usually near).
constexpr int kKeyShiftCandidates = 3;
constexpr int kShiftNeighbours = 2;
// Fewer sectors than this share of the smaller descriptor's used sectors in common at a shift: the
// shift compares too little to mean anything. With a third, 180-degree scans matched wrong places
// at shifts near 110 degrees, where a few look-alike columns are all that is compared.
constexpr double kMinOverlap = 0.5;

void check_grid(const char* what, int rings, int sectors, double max_range) {
  if (rings < 1 || sectors < 1 || !(max_range > 0.0))
    fail("place descriptor", std::string(what) + ": rings and sectors must be at least 1 and " +
                                 "max_range positive (got " + std::to_string(rings) + ", " +
                                 std::to_string(sectors) + ", " + std::to_string(max_range) + ")");
}

void start_grid(PlaceDescriptor& d, int rings, int sectors) {
  d.rings = rings;
  d.sectors = sectors;
  d.cells.assign(static_cast<std::size_t>(rings) * static_cast<std::size_t>(sectors), 0.0f);
  d.column_used.assign(static_cast<std::size_t>(sectors), false);
}

int sector_of(double x, double y, int sectors) {
  double bearing = std::atan2(y, x);
  if (bearing < 0.0) bearing += 2.0 * M_PI;
  const int s = static_cast<int>(bearing * sectors / (2.0 * M_PI));
  return std::min(s, sectors - 1);  // bearing rounding up to exactly 2 pi
}

void fill_sector_key(PlaceDescriptor& d) {
  d.sector_key.assign(static_cast<std::size_t>(d.sectors), 0.0f);
  for (int s = 0; s < d.sectors; ++s) {
    const float* column = &d.cells[static_cast<std::size_t>(s * d.rings)];
    float sum = 0.0f;
    for (int r = 0; r < d.rings; ++r) sum += column[r];
    d.sector_key[static_cast<std::size_t>(s)] = sum / static_cast<float>(d.rings);
  }
}

bool comparable(const PlaceDescriptor& a, const PlaceDescriptor& b) {
  return !a.empty() && !b.empty() && a.rings == b.rings && a.sectors == b.sectors;
}

std::size_t min_overlap(const PlaceDescriptor& a, const PlaceDescriptor& b) {
  const std::size_t smaller = std::min(a.used_columns(), b.used_columns());
  return std::max<std::size_t>(
      1, static_cast<std::size_t>(std::ceil(kMinOverlap * static_cast<double>(smaller))));
}

// Mean |difference| of the sector keys over the sectors both use, query sector j against
// candidate sector j + shift; infinity when too few overlap.
double sector_key_distance(const PlaceDescriptor& q, const PlaceDescriptor& c, int shift,
                           std::size_t needed) {
  double sum = 0.0;
  std::size_t overlap = 0;
  for (int j = 0; j < q.sectors; ++j) {
    const auto qj = static_cast<std::size_t>(j);
    const auto cj = static_cast<std::size_t>((j + shift) % q.sectors);
    if (!q.column_used[qj] || !c.column_used[cj]) continue;
    sum += std::abs(q.sector_key[qj] - c.sector_key[cj]);
    ++overlap;
  }
  return overlap < needed ? std::numeric_limits<double>::infinity()
                          : sum / static_cast<double>(overlap);
}

// Mean 1 - cosine similarity of the columns both use at `shift`; 1 when too few overlap.
double grid_distance(const PlaceDescriptor& q, const PlaceDescriptor& c, int shift,
                     std::size_t needed) {
  double sum = 0.0;
  std::size_t overlap = 0;
  for (int j = 0; j < q.sectors; ++j) {
    const int k = (j + shift) % q.sectors;
    if (!q.column_used[static_cast<std::size_t>(j)] || !c.column_used[static_cast<std::size_t>(k)])
      continue;
    const float* a = &q.cells[static_cast<std::size_t>(j * q.rings)];
    const float* b = &c.cells[static_cast<std::size_t>(k * q.rings)];
    double dot = 0.0, aa = 0.0, bb = 0.0;
    for (int r = 0; r < q.rings; ++r) {
      dot += static_cast<double>(a[r]) * b[r];
      aa += static_cast<double>(a[r]) * a[r];
      bb += static_cast<double>(b[r]) * b[r];
    }
    // Columns with points all at height 0: alike when both are, unlike a column with height.
    const double cosine = aa > 0.0 && bb > 0.0 ? dot / std::sqrt(aa * bb) : (aa == bb ? 1.0 : 0.0);
    sum += 1.0 - std::clamp(cosine, 0.0, 1.0);
    ++overlap;
  }
  return overlap < needed ? 1.0 : sum / static_cast<double>(overlap);
}

PlaceMatch compare_grids(const PlaceDescriptor& q, const PlaceDescriptor& c) {
  if (!comparable(q, c)) return {};
  const int sectors = q.sectors;
  const std::size_t needed = min_overlap(q, c);
  std::vector<std::pair<double, int>> by_key;
  by_key.reserve(static_cast<std::size_t>(sectors));
  for (int shift = 0; shift < sectors; ++shift) {
    const double d = sector_key_distance(q, c, shift, needed);
    if (std::isfinite(d)) by_key.emplace_back(d, shift);
  }
  if (by_key.empty()) return {};
  const std::size_t keep = std::min<std::size_t>(kKeyShiftCandidates, by_key.size());
  std::partial_sort(by_key.begin(), by_key.begin() + static_cast<long>(keep), by_key.end());

  std::vector<double> distance(static_cast<std::size_t>(sectors), -1.0);  // -1: not evaluated
  const auto wrap = [sectors](int s) { return ((s % sectors) + sectors) % sectors; };
  const auto at = [&](int s) {
    double& d = distance[static_cast<std::size_t>(wrap(s))];
    if (d < 0.0) d = grid_distance(q, c, wrap(s), needed);
    return d;
  };
  int best = -1;
  double best_distance = 2.0;
  for (std::size_t i = 0; i < keep; ++i)
    for (int n = -kShiftNeighbours; n <= kShiftNeighbours; ++n) {
      const int s = wrap(by_key[i].second + n);
      if (at(s) < best_distance) {
        best_distance = at(s);
        best = s;
      }
    }
  if (best_distance >= 1.0) return {};
  // Between sectors: the vertex of the parabola through the best shift and its neighbours.
  const double before = at(best - 1), after = at(best + 1);
  const double curvature = before - 2.0 * best_distance + after;
  const double offset = sectors > 2 && curvature > 0.0
                            ? std::clamp(0.5 * (before - after) / curvature, -0.5, 0.5)
                            : 0.0;
  double yaw = (best + offset) * 2.0 * M_PI / sectors;
  if (yaw > M_PI) yaw -= 2.0 * M_PI;
  return {best_distance, yaw};
}

}  // namespace

std::size_t PlaceDescriptor::used_columns() const {
  return static_cast<std::size_t>(std::count(column_used.begin(), column_used.end(), true));
}

PlaceDescriptor3D make_place_descriptor(const PointCloud& cloud,
                                        const PlaceDescriptorOptions& options) {
  check_grid("3D options", options.rings, options.sectors, options.max_range);
  PlaceDescriptor3D d;
  start_grid(d, options.rings, options.sectors);
  std::vector<bool> occupied(d.cells.size(), false);
  const double ring_width = options.max_range / options.rings;
  std::size_t used = 0;
  for (const Point& p : cloud.points) {
    if (!p.allFinite()) continue;
    const double range = std::hypot(static_cast<double>(p.x()), static_cast<double>(p.y()));
    if (range >= options.max_range) continue;
    const int ring = std::min(static_cast<int>(range / ring_width), options.rings - 1);
    const int sector = sector_of(p.x(), p.y(), options.sectors);
    const std::size_t cell = static_cast<std::size_t>(sector * options.rings + ring);
    const float height = std::max(0.0f, p.z() + static_cast<float>(options.height_offset));
    d.cells[cell] = std::max(d.cells[cell], height);
    occupied[cell] = true;
    d.column_used[static_cast<std::size_t>(sector)] = true;
    ++used;
  }
  if (used == 0) return {};  // no sizes either: compares with nothing
  d.ring_key.assign(static_cast<std::size_t>(d.rings), 0.0f);
  for (int s = 0; s < d.sectors; ++s)
    for (int r = 0; r < d.rings; ++r)
      if (occupied[static_cast<std::size_t>(s * d.rings + r)])
        d.ring_key[static_cast<std::size_t>(r)] += 1.0f / static_cast<float>(d.sectors);
  fill_sector_key(d);
  return d;
}

PlaceDescriptor2D make_place_descriptor(const Scan2D& scan,
                                        const PlaceDescriptor2DOptions& options) {
  check_grid("2D options", options.rings, options.sectors, options.max_range);
  PlaceDescriptor2D d;
  start_grid(d, options.rings, options.sectors);
  std::vector<int> beams(static_cast<std::size_t>(d.sectors), 0);
  const double ring_width = options.max_range / options.rings;
  const auto add_beam = [&](const Eigen::Vector2d& p, bool reaches_max_range) {
    if (!p.allFinite()) return;
    const double range = reaches_max_range ? options.max_range : p.norm();
    const int sector = sector_of(p.x(), p.y(), options.sectors);
    float* column = &d.cells[static_cast<std::size_t>(sector * d.rings)];
    // The part of each ring's width the beam crosses before its return.
    for (int r = 0; r < d.rings; ++r) {
      const double free = (range - r * ring_width) / ring_width;
      if (free <= 0.0) break;
      column[r] += static_cast<float>(std::min(free, 1.0));
    }
    ++beams[static_cast<std::size_t>(sector)];
  };
  for (const Eigen::Vector2d& p : scan.points) add_beam(p, false);
  for (const Eigen::Vector2d& p : scan.misses) add_beam(p, true);
  d.ring_key.assign(static_cast<std::size_t>(d.rings), 0.0f);
  std::size_t used = 0;
  for (int s = 0; s < d.sectors; ++s) {
    const int n = beams[static_cast<std::size_t>(s)];
    if (n == 0) continue;
    d.column_used[static_cast<std::size_t>(s)] = true;
    ++used;
    float* column = &d.cells[static_cast<std::size_t>(s * d.rings)];
    for (int r = 0; r < d.rings; ++r) {
      column[r] /= static_cast<float>(n);
      d.ring_key[static_cast<std::size_t>(r)] += column[r];
    }
  }
  if (used == 0) return {};
  for (float& k : d.ring_key) k /= static_cast<float>(used);
  fill_sector_key(d);
  return d;
}

PlaceMatch compare(const PlaceDescriptor3D& query, const PlaceDescriptor3D& candidate) {
  return compare_grids(query, candidate);
}
PlaceMatch compare(const PlaceDescriptor2D& query, const PlaceDescriptor2D& candidate) {
  return compare_grids(query, candidate);
}

}  // namespace scanmatch
