#pragma once
// Floor plans for the 2D tests: wall segments, the range along a ray to the nearest, and the yard
// of building fronts the weaving and loop tests drive in.

#include <Eigen/Core>
#include <Eigen/LU>
#include <cmath>
#include <limits>
#include <vector>

namespace scanmatch::testing {

struct Segment {
  Eigen::Vector2d a, b;
};

/// The range along the ray from `origin` in direction `d` to the nearest of `walls`; infinity
/// where it meets none.
inline double nearest_wall(const std::vector<Segment>& walls, const Eigen::Vector2d& origin,
                           const Eigen::Vector2d& d) {
  double best = std::numeric_limits<double>::infinity();
  for (const Segment& w : walls) {
    // origin + t d = a + s (b - a)
    Eigen::Matrix2d A;
    A << d, w.a - w.b;
    if (std::abs(A.determinant()) < 1e-12) continue;
    const Eigen::Vector2d ts = A.inverse() * (w.a - origin);
    if (ts.x() > 0 && ts.y() >= 0 && ts.y() <= 1) best = std::min(best, ts.x());
  }
  return best;
}

/// A yard of building fronts about 26 x 21 m, open on one side, with a block and two free-standing
/// walls in it (nothing repeats).
inline std::vector<Segment> yard_fronts() {
  return {{{-8, -9}, {18, -9}}, {{18, -9}, {18, 2}}, {{18, 5}, {18, 12}}, {{18, 12}, {-8, 12}},
          {{-8, 12}, {-8, -9}}, {{7, 3}, {10, 3}},   {{10, 3}, {10, 6}},  {{10, 6}, {7, 6}},
          {{7, 6}, {7, 3}},     {{-3, -6}, {2, -5}}, {{14, 9}, {16, 10}}};
}

}  // namespace scanmatch::testing
