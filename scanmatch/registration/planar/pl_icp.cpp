// pl-icp: Censi's point-to-line ICP. Each point is matched against the line through its nearest
// reference point and the nearer of that point's two beam-order neighbours (or, with
// pl_line_radius, the line fitted there); the worst pairs beyond keep_fraction are dropped, and
// the exact closed-form step (point_to_line.hpp) solves the rest.

#include <algorithm>
#include <cmath>
#include <limits>

#include "scanmatch/registration/planar/common.hpp"
#include "scanmatch/registration/planar/point_to_line.hpp"
#include "scanmatch/registration/planar/reference2d.hpp"
#include "scanmatch/registration/planar/registration2d.hpp"

namespace scanmatch {

// The pl-icp line of the method table (registration2d.cpp).
Registration2DResult run_pl_icp(const Scan2D& current, const Reference2D& prepared,
                                const Registration2DOptions& o, const Pose2& initial) {
  using Vec2 = Eigen::Vector2d;
  const Scan2D& reference = prepared.scan();
  const PointGrid2& points = prepared.grid();
  const double max_squared = o.max_correspondence_distance * o.max_correspondence_distance;
  const std::vector<FittedLine> no_lines;
  const std::vector<FittedLine>& lines =
      o.pl_line_radius > 0.0 ? prepared.lines(o.pl_line_radius, o.max_correspondence_distance)
                             : no_lines;
  std::vector<planar::LinePair> pairs;
  Registration2DResult r;
  r.transform = initial;
  planar::IterationCycle cycle;  // a pose met again: the rest repeats
  for (r.iterations = 1; r.iterations <= o.max_iterations; ++r.iterations) {
    pairs.clear();
    for (const Vec2& point : current.points) {
      const Vec2 p = r.transform * point;
      std::size_t j = 0;
      double squared = 0.0;
      if (!points.nearest(p, max_squared, j, squared)) continue;
      if (!lines.empty() && !lines[j].normal.isZero()) {
        const FittedLine& line = lines[j];
        pairs.push_back(
            {point, line.point, line.normal, std::abs(line.normal.dot(p - line.point))});
        continue;
      }
      // The second point: the nearer beam-order neighbour of j, if it is close enough to be on
      // the same surface.
      double best = std::numeric_limits<double>::infinity();
      std::size_t k = j;
      for (const long step : {-1L, 1L}) {
        const long candidate = beam_neighbour(reference, j, step);
        if (candidate < 0) continue;
        const double d = (reference.points[static_cast<std::size_t>(candidate)] - p).squaredNorm();
        if (d < best) {
          best = d;
          k = static_cast<std::size_t>(candidate);
        }
      }
      const Vec2 direction = reference.points[k] - reference.points[j];
      if (k == j || direction.norm() < 1e-9 || direction.norm() > 2 * o.max_correspondence_distance)
        continue;
      const Vec2 normal = Vec2(-direction.y(), direction.x()).normalized();
      pairs.push_back(
          {point, reference.points[j], normal, std::abs(normal.dot(p - reference.points[j]))});
    }
    if (pairs.size() < 3) break;
    planar::keep_nearest_fraction(pairs, o.keep_fraction);
    r.pairs = pairs.size();
    const Pose2 next = planar::solve_line_pairs(pairs, r.transform, r.error);
    const Pose2 step = next * r.transform.inverse();
    r.transform = next;
    if (planar::small_step(step, o.tolerance)) {
      r.converged = true;
      break;
    }
    if (cycle.closes(r, o.max_iterations)) break;  // the limit's outcome, known
  }
  r.iterations = std::min(r.iterations, o.max_iterations);
  return r;
}

}  // namespace scanmatch
