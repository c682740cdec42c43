#include "scanmatch/registration/planar/sparse_icp.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "scanmatch/features/angle_histogram.hpp"
#include "scanmatch/registration/planar/common.hpp"
#include "scanmatch/registration/planar/correspondence_path.hpp"
#include "scanmatch/registration/planar/line_fitting.hpp"
#include "scanmatch/registration/planar/point_to_line.hpp"
#include "scanmatch/registration/planar/point_to_point.hpp"
#include "scanmatch/registration/planar/reference2d.hpp"
#include "scanmatch/registration/planar/registration2d.hpp"

namespace scanmatch {
namespace {

using Vec2 = Eigen::Vector2d;

}  // namespace

Pose2 coarse_alignment_2d(const std::vector<Vec2>& current, const std::vector<Vec2>& reference,
                          double bin_width, double max_rotation, bool rotation, bool translation,
                          double min_segment) {
  Pose2 correction = Pose2::Identity();
  if (rotation) {
    const double angle =
        histogram_rotation(angle_histogram(current, bin_width, 0.5, min_segment),
                           angle_histogram(reference, bin_width, 0.5, min_segment), max_rotation);
    correction.linear() = Eigen::Rotation2Dd(angle).toRotationMatrix();
  }
  if (translation)
    correction.translation() =
        planar::centroid(reference) - correction.linear() * planar::centroid(current);
  return correction;
}

// The sparse-icp line of the method table (registration2d.cpp).
Registration2DResult run_sparse_icp(const Scan2D& current, const Reference2D& prepared,
                                    const Registration2DOptions& o, const Pose2& initial) {
  const Scan2D& reference = prepared.scan();
  // The correlative search, when it ran, replaces the coarse stage.
  const bool coarse = !(o.search_window > 0.0);
  Registration2DResult r;
  r.transform = initial;
  if (coarse && (o.coarse_rotation || o.coarse_translation))
    r.transform =
        coarse_alignment_2d(planar::transformed(current.points, initial), reference.points,
                            o.histogram_bin, o.histogram_max_rotation, o.coarse_rotation,
                            o.coarse_translation, o.histogram_min_segment) *
        initial;
  planar::PointPairs pairs;
  std::vector<planar::LinePair> line_pairs;
  const bool point_to_line = o.sparse_step == "point-to-line";
  PathTracer path_tracer(reference.points, reference.circular, o.max_correspondence_distance,
                         o.path_rules);
  const std::vector<FittedLine> no_lines;
  const std::vector<FittedLine>& lines =
      point_to_line && o.sparse_line_radius > 0.0
          ? prepared.lines(o.sparse_line_radius, o.max_correspondence_distance)
          : no_lines;
  planar::IterationCycle cycle;  // a pose met again: the rest repeats
  for (r.iterations = 1; r.iterations <= o.max_iterations; ++r.iterations) {
    const std::vector<Vec2> moved = planar::transformed(current.points, r.transform);
    const CorrespondencePath path = path_tracer.trace(moved);
    pairs.clear();
    line_pairs.clear();
    for (std::size_t i = 0; i < moved.size(); ++i) {
      if (!path.valid[i]) continue;
      const std::size_t j = static_cast<std::size_t>(path.row[i]);
      if (point_to_line) {
        if (!lines.empty() && !lines[j].normal.isZero()) {
          const FittedLine& line = lines[j];
          // Beyond the end of the surface (see project_onto_neighbour_segments), or beyond the
          // stretch the line was fitted to (a run of current points on one reference point can
          // reach far along it): no pair.
          const Vec2 offset = moved[i] - line.point;
          if ((moved[i] - reference.points[j]).dot(line.inward) < 0.0 ||
              std::abs(offset.x() * line.normal.y() - offset.y() * line.normal.x()) >
                  o.sparse_line_radius)
            continue;
          line_pairs.push_back({current.points[i], line.point, line.normal,
                                std::abs(line.normal.dot(moved[i] - line.point))});
          continue;
        }
        const auto projected =
            project_onto_neighbour_segments(reference, j, moved[i], o.max_correspondence_distance);
        if (!projected || projected->normal.isZero()) continue;
        const Vec2& n = projected->normal;
        line_pairs.push_back({current.points[i], reference.points[j], n,
                              std::abs(n.dot(moved[i] - reference.points[j]))});
        continue;
      }
      Vec2 q = reference.points[j];
      if (o.subsample_projection) {
        const auto projected =
            project_onto_neighbour_segments(reference, j, moved[i], o.max_correspondence_distance);
        if (!projected) continue;
        q = projected->point;
      }
      pairs.from.push_back(current.points[i]);
      pairs.to.push_back(q);
      pairs.distance_sum += (moved[i] - q).norm();
    }
    // Too few pairs left: the path no longer follows a surface both scans saw, and steps taken
    // on what is left wander off (up to 170 deg on FHW from a poor start). Stop where we are.
    const std::size_t kept = point_to_line ? line_pairs.size() : pairs.from.size();
    if (static_cast<double>(kept) < std::max(3.0, o.sparse_min_pairs * moved.size())) {
      r.pairs = kept;
      break;
    }
    Pose2 next;
    if (point_to_line) {
      if (o.sparse_keep_fraction < 1.0)
        planar::keep_nearest_fraction(line_pairs, o.sparse_keep_fraction);
      r.pairs = line_pairs.size();
      next = planar::solve_line_pairs(line_pairs, r.transform, r.error);
    } else {
      r.pairs = pairs.from.size();
      next = align_svd(pairs.from, pairs.to);
      r.error = pairs.distance_sum / static_cast<double>(r.pairs);
    }
    const Pose2 step = next * r.transform.inverse();
    r.transform = next;
    if (planar::small_step(step, std::max(o.tolerance, o.sparse_tolerance))) {
      r.converged = true;
      break;
    }
    if (cycle.closes(r, o.max_iterations)) break;  // the limit's outcome, known
  }
  r.iterations = std::min(r.iterations, o.max_iterations);
  return r;
}

}  // namespace scanmatch
