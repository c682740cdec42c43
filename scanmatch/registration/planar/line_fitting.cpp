#include "scanmatch/registration/planar/line_fitting.hpp"

#include <algorithm>
#include <cmath>

namespace scanmatch {

using Vec2 = Eigen::Vector2d;

std::vector<FittedLine> fit_scan_lines(const Scan2D& scan, double radius, double max_gap) {
  const long m = static_cast<long>(scan.points.size());
  std::vector<FittedLine> lines(scan.points.size());
  const double radius_squared = radius * radius, gap_squared = max_gap * max_gap;
  for (long j = 0; j < m; ++j) {
    const Vec2& centre = scan.points[static_cast<std::size_t>(j)];
    // Sums relative to the centre point keep the covariance well conditioned.
    Vec2 sum = Vec2::Zero();
    double xx = 0, xy = 0, yy = 0;
    int count = 1;
    long first_neighbour[2] = {-1, -1};
    for (int side = 0; side < 2; ++side) {
      long previous = j;
      for (long walked = 1; walked < m; ++walked) {
        const long k = beam_neighbour(m, scan.circular, previous, side == 0 ? -1 : 1);
        if (k < 0 || k == j) break;
        const Vec2& q = scan.points[static_cast<std::size_t>(k)];
        if ((q - scan.points[static_cast<std::size_t>(previous)]).squaredNorm() > gap_squared ||
            (q - centre).squaredNorm() > radius_squared)
          break;
        if (walked == 1) first_neighbour[side] = k;
        const Vec2 d = q - centre;
        sum += d;
        xx += d.x() * d.x();
        xy += d.x() * d.y();
        yy += d.y() * d.y();
        ++count;
        previous = k;
      }
    }
    if (count < 3) continue;
    const Vec2 mean = sum / count;
    const double a = xx / count - mean.x() * mean.x(), b = xy / count - mean.x() * mean.y(),
                 c = yy / count - mean.y() * mean.y();
    // Eigenvalues of [a b; b c] in closed form; the normal is the minor axis.
    const double half_difference = 0.5 * (a - c), root = std::hypot(half_difference, b);
    const double major = 0.5 * (a + c) + root, minor = 0.5 * (a + c) - root;
    if (minor > 0.0625 * major) continue;
    Vec2 axis = a >= c ? Vec2(major - c, b) : Vec2(b, major - a);
    if (axis.squaredNorm() < 1e-30) continue;
    axis.normalize();
    FittedLine& line = lines[static_cast<std::size_t>(j)];
    line.point = centre + mean;
    line.normal = Vec2(-axis.y(), axis.x());
    const bool open[2] = {first_neighbour[0] < 0, first_neighbour[1] < 0};
    if (open[0] != open[1]) {
      const long inside = first_neighbour[open[0] ? 1 : 0];
      line.inward = (scan.points[static_cast<std::size_t>(inside)] - centre).normalized();
    }
  }
  return lines;
}

std::optional<SegmentProjection> project_onto_neighbour_segments(const Scan2D& reference,
                                                                 std::size_t j, const Vec2& p,
                                                                 double max_length) {
  const Vec2& q = reference.points[j];
  SegmentProjection best{q, Vec2::Zero()};
  double best_squared = (p - q).squaredNorm();
  int segments = 0;
  bool beyond = false;
  for (const long step : {-1L, 1L}) {
    const long k = beam_neighbour(reference, j, step);
    if (k < 0) continue;
    const Vec2 d = reference.points[static_cast<std::size_t>(k)] - q;
    const double length_squared = d.squaredNorm();
    if (length_squared < 1e-18 || length_squared > max_length * max_length) continue;
    ++segments;
    const double along = (p - q).dot(d) / length_squared;
    beyond = along < 0.0;
    const Vec2 candidate = q + std::clamp(along, 0.0, 1.0) * d;
    const double squared = (p - candidate).squaredNorm();
    // The first usable segment always counts (its nearest point is never farther than j).
    if (squared < best_squared || best.normal.isZero()) {
      best_squared = squared;
      best = {candidate, Vec2(-d.y(), d.x()) / std::sqrt(length_squared)};
    }
  }
  if (segments == 1 && beyond) return std::nullopt;
  return best;
}

}  // namespace scanmatch
