#include "scanmatch/registration/planar/correspondence_path.hpp"

#include <algorithm>
#include <cmath>

#include "scanmatch/core/error.hpp"
#include "scanmatch/core/scan2d.hpp"

namespace scanmatch {

using Vec2 = Eigen::Vector2d;

const char* to_string(PathRules::Shared shared) {
  switch (shared) {
    case PathRules::Shared::drop:
      return "drop";
    case PathRules::Shared::keep_nearest:
      return "keep-nearest";
    case PathRules::Shared::keep_all:
      return "keep-all";
  }
  return "?";
}

PathRules::Shared parse_shared_rows(const std::string& name) {
  for (const auto shared :
       {PathRules::Shared::drop, PathRules::Shared::keep_nearest, PathRules::Shared::keep_all})
    if (name == to_string(shared)) return shared;
  throw Error("unknown shared-rows rule '" + name + "' (drop, keep-nearest, keep-all)");
}

CorrespondencePath correspondence_path(const std::vector<Vec2>& current,
                                       const std::vector<Vec2>& reference, bool circular,
                                       double max_distance, const PathRules& rules) {
  return PathTracer(reference, circular, max_distance, rules).trace(current);
}

PathTracer::PathTracer(const std::vector<Vec2>& reference, bool circular, double max_distance,
                       const PathRules& rules)
    : reference_(reference), circular_(circular), max_distance_(max_distance), rules_(rules) {}

PathTracer::BearingIndex::BearingIndex(const std::vector<Vec2>& points) {
  sorted.reserve(points.size());
  for (std::size_t j = 0; j < points.size(); ++j)
    sorted.emplace_back(std::atan2(points[j].y(), points[j].x()), static_cast<long>(j));
  std::sort(sorted.begin(), sorted.end());
}

long PathTracer::BearingIndex::nearest(const Vec2& p) const {
  const double bearing = std::atan2(p.y(), p.x());
  auto after = std::lower_bound(sorted.begin(), sorted.end(), std::make_pair(bearing, -1L));
  if (after == sorted.end()) after = sorted.begin();  // wraps past +pi
  const auto before = after == sorted.begin() ? sorted.end() - 1 : after - 1;
  const auto gap = [&](double b) { return std::abs(std::remainder(b - bearing, 2 * M_PI)); };
  return gap(before->first) < gap(after->first) ? before->second : after->second;
}

CorrespondencePath PathTracer::trace(const std::vector<Vec2>& current) {
  const std::vector<Vec2>& reference = reference_;
  const bool circular = circular_;
  const double max_distance = max_distance_;
  const PathRules& rules = rules_;
  const long n = static_cast<long>(current.size()), m = static_cast<long>(reference.size());
  CorrespondencePath path;
  path.row.assign(static_cast<std::size_t>(n), 0);
  path.valid.assign(static_cast<std::size_t>(n), false);
  if (n == 0 || m == 0) return path;
  const auto distance = [&](long i, long j) {
    const Vec2 d = current[static_cast<std::size_t>(i)] - reference[static_cast<std::size_t>(j)];
    return std::abs(d.x()) + std::abs(d.y());
  };
  // Rows outside the scan do not exist for an open scan; a circular scan wraps.
  const auto neighbour = [&](long j, long step) { return beam_neighbour(m, circular, j, step); };
  const auto row_step = [&](long from, long to) {
    long d = to - from;
    if (circular) {
      if (d > m / 2) d -= m;
      if (d < -m / 2) d += m;
    }
    return d;
  };
  // The 3x1 window slides from row j towards decreasing distance until its centre is the minimum.
  const auto slide = [&](long i, long& j, double& d) {
    for (long moves = 0; moves < m; ++moves) {
      long best = j;
      double best_d = d;
      for (const long step : {-1L, 1L}) {
        const long k = neighbour(j, step);
        if (k < 0) continue;
        const double dk = distance(i, k);
        if (dk < best_d) {
          best = k;
          best_d = dk;
        }
      }
      if (best == j) return;
      j = best;
      d = best_d;
    }
  };

  std::vector<double> best_distance(static_cast<std::size_t>(n));
  long j = 0;  // the path starts at the minimum of the first column
  for (long k = 1; k < m; ++k)
    if (distance(0, k) < distance(0, j)) j = k;
  for (long i = 0; i < n; ++i) {
    double d = distance(i, j);
    if (i > 0) {
      slide(i, j, d);
      if (d > max_distance) {
        // Lost (an occlusion or a gap): pick the path up again at the reference beam nearest in
        // bearing, where the reference would have seen this point, and slide from there.
        if (!bearings_) bearings_.emplace(reference);  // built once, when first needed
        const long seed = bearings_->nearest(current[static_cast<std::size_t>(i)]);
        double seed_d = distance(i, seed);
        long seed_j = seed;
        slide(i, seed_j, seed_d);
        if (seed_d < d) {
          j = seed_j;
          d = seed_d;
        }
      }
    }
    path.row[static_cast<std::size_t>(i)] = static_cast<int>(j);
    best_distance[static_cast<std::size_t>(i)] = d;
  }
  // Invalid pairs: abnormal steps (repeat = many-to-one, skip = one-to-many, backwards, jumps),
  // shared reference points and distances above the threshold. What is left is one-to-one.
  // Relaxed (not the paper): a skip of up to `max_step` rows is normal; of the columns that share
  // a row the nearest keeps it, or all do (a run on one row is then one normal step).
  const auto at = [&](long k) { return static_cast<long>(path.row[static_cast<std::size_t>(k)]); };
  const auto dist = [&](long k) { return best_distance[static_cast<std::size_t>(k)]; };
  const long max_step = rules.max_step;
  for (long i = 0; i < n; ++i) {
    const auto normal_step = [&](long from, long to) {
      const long d = row_step(at(from), at(to));
      return d >= 1 && d <= max_step;
    };
    bool normal = i > 0 ? normal_step(i - 1, i) : (i + 1 < n && normal_step(i, i + 1));
    bool shared = (i > 0 && at(i - 1) == at(i)) || (i + 1 < n && at(i + 1) == at(i));
    if (shared && rules.shared != PathRules::Shared::drop) {
      // The run of columns on this row, judged by the steps into and out of it.
      long first = i, last = i;
      while (first > 0 && at(first - 1) == at(i)) --first;
      while (last + 1 < n && at(last + 1) == at(i)) ++last;
      normal = (first > 0 && normal_step(first - 1, first)) ||
               (last + 1 < n && normal_step(last, last + 1));
      if (rules.shared == PathRules::Shared::keep_all && last - first < rules.max_run) {
        shared = false;
      } else {
        long nearest = first;
        for (long k = first + 1; k <= last; ++k)
          if (dist(k) < dist(nearest)) nearest = k;
        shared = nearest != i;
      }
    }
    path.valid[static_cast<std::size_t>(i)] = normal && !shared && dist(i) <= max_distance;
  }
  return path;
}

}  // namespace scanmatch
