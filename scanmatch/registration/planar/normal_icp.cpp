// normal-icp: point-to-point ICP (k-d tree) with pairs rejected when their normals disagree.

#include <cmath>

#include "scanmatch/registration/planar/point_to_point.hpp"
#include "scanmatch/registration/planar/reference2d.hpp"

namespace scanmatch {
namespace {

using Vec2 = Eigen::Vector2d;

/// Unit normals of a scan from its beam-order neighbours; zero where a point has no neighbour
/// within `max_gap` on either side (an isolated return has no surface direction).
std::vector<Vec2> scan_normals(const std::vector<Vec2>& points, bool circular, double max_gap) {
  const long n = static_cast<long>(points.size());
  std::vector<Vec2> normals(points.size(), Vec2::Zero());
  for (long i = 0; i < n; ++i) {
    const Vec2& p = points[static_cast<std::size_t>(i)];
    Vec2 ends[2] = {p, p};  // the neighbours before and after, where near enough
    for (int side = 0; side < 2; ++side) {
      const long k = beam_neighbour(n, circular, i, side == 0 ? -1 : 1);
      if (k >= 0 && (points[static_cast<std::size_t>(k)] - p).norm() < max_gap)
        ends[side] = points[static_cast<std::size_t>(k)];
    }
    const Vec2 d = ends[1] - ends[0];
    if (d.norm() > 1e-9) normals[static_cast<std::size_t>(i)] = Vec2(-d.y(), d.x()).normalized();
  }
  return normals;
}

}  // namespace

// The normal-icp line of the method table (registration2d.cpp).
Registration2DResult run_normal_icp(const Scan2D& current, const Reference2D& prepared,
                                    const Registration2DOptions& o, const Pose2& initial) {
  const Scan2D& reference = prepared.scan();
  const double gap = 3 * o.max_correspondence_distance;
  const std::vector<Vec2> reference_normals =
      scan_normals(reference.points, reference.circular, gap);
  const std::vector<Vec2> current_normals = scan_normals(current.points, current.circular, gap);
  const double min_cos = std::cos(o.normal_angle);
  const auto normals_agree = [&](std::size_t i, std::size_t j, const Eigen::Matrix2d& R) {
    const Vec2& nr = reference_normals[j];
    const Vec2 nc = R * current_normals[i];
    return !(nr.isZero() || nc.isZero() || std::abs(nr.dot(nc)) < min_cos);
  };
  return planar::point_to_point_icp(current, prepared, o, initial, true, normals_agree);
}

}  // namespace scanmatch
