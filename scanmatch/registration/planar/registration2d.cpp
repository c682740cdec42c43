#include "scanmatch/registration/planar/registration2d.hpp"

#include <algorithm>
#include <cmath>

#include "scanmatch/core/error.hpp"
#include "scanmatch/registration/planar/correlative_search.hpp"
#include "scanmatch/registration/planar/line_fitting.hpp"
#include "scanmatch/registration/planar/reference2d.hpp"

namespace scanmatch {

// The methods' run functions, each defined in its own file of registration/planar/.
Registration2DRun run_sparse_icp, run_icp, run_icp_kdtree, run_pl_icp, run_normal_icp;

namespace {

void check_scan(const Scan2D& scan, const char* which, std::size_t min_points) {
  if (scan.points.size() < min_points)
    throw Error(std::string("2D registration: the ") + which + " scan has " +
                std::to_string(scan.points.size()) + " valid points, at least " +
                std::to_string(min_points) + " are needed");
  for (const Eigen::Vector2d& p : scan.points)
    if (!p.allFinite())
      throw Error(std::string("2D registration: the ") + which + " scan has a non-finite point");
}

/// The options' method, after checking the options and both scans.
const Registration2DMethod& checked_method(const Scan2D& current, const Scan2D& reference,
                                           const Registration2DOptions& o) {
  const Registration2DMethod& method = registration_2d_method(o.method);
  check_registration_2d_options(o);
  check_scan(current, "current", method.min_points);
  check_scan(reference, "reference", method.min_points);
  return method;
}

}  // namespace

const std::vector<Registration2DMethod>& registration_2d_methods() {
  // The method table: a new 2D method is a file with its run function and a line here.
  static const std::vector<Registration2DMethod> methods = {
      {"sparse-icp", 5, "lines fitted to the reference; its bearing index once the path is lost",
       run_sparse_icp},
      {"icp", 5, "nothing (brute-force nearest neighbours)", run_icp},
      {"icp-kdtree", 5, "a k-d tree of the reference", run_icp_kdtree},
      {"pl-icp", 5, "a grid of the reference's points (and its fitted lines with pl_line_radius)",
       run_pl_icp},
      {"normal-icp", 5, "a k-d tree of the reference; normals of both scans", run_normal_icp},
  };
  return methods;
}

const std::vector<std::string>& registration_2d_method_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const Registration2DMethod& m : registration_2d_methods()) out.emplace_back(m.name);
    return out;
  }();
  return names;
}

std::string registration_2d_method_list() {
  std::string list;
  for (const Registration2DMethod& m : registration_2d_methods())
    list += (list.empty() ? "" : ", ") + std::string(m.name);
  return list;
}

const Registration2DMethod& registration_2d_method(const std::string& name) {
  for (const Registration2DMethod& m : registration_2d_methods())
    if (name == m.name) return m;
  throw Error("unknown 2D registration method '" + name +
              "' (valid: " + registration_2d_method_list() + ")");
}

void check_registration_2d_method(const std::string& method) {
  registration_2d_method(method);
}

void check_registration_2d_options(const Registration2DOptions& o) {
  check_registration_2d_method(o.method);
  if (!(o.max_correspondence_distance > 0.0))
    throw Error("2D registration: the correspondence distance must be positive");
  if (o.max_iterations < 1) throw Error("2D registration: at least one iteration is needed");
  if (o.sparse_step != "svd" && o.sparse_step != "point-to-line")
    throw Error("2D registration: unknown sparse-icp step '" + o.sparse_step +
                "' (svd, point-to-line)");
  if (o.path_rules.max_step < 1 || o.path_rules.max_run < 1)
    throw Error("2D registration: the path's max step and max run must be at least 1");
  if (!(o.sparse_line_radius >= 0.0) || !(o.pl_line_radius >= 0.0))
    throw Error("2D registration: a line radius must be 0 or positive");
  if (!(o.sparse_keep_fraction > 0.0 && o.sparse_keep_fraction <= 1.0) ||
      !(o.keep_fraction > 0.0 && o.keep_fraction <= 1.0))
    throw Error("2D registration: a keep fraction must be in (0, 1]");
  if (!(o.sparse_min_pairs >= 0.0 && o.sparse_min_pairs < 1.0))
    throw Error("2D registration: sparse_min_pairs must be in [0, 1)");
  if (!(o.search_fill_gap >= 0.0))
    throw Error("2D registration: search_fill_gap must not be negative");
  if (std::isnan(o.fine_fit_margin))
    throw Error("2D registration: fine_fit_margin must be a number (negative: off)");
}

namespace {

/// surface_distance against one reference, for any number of poses.
class SurfaceDistance {
 public:
  SurfaceDistance(const Reference2D& reference, double max_gap, double cap)
      : reference_(reference), max_gap_(max_gap), cap_(cap) {}

  double operator()(const Scan2D& current, const Pose2& pose) const {
    if (current.points.empty() || reference_.scan().points.empty()) return cap_;
    // A segment within `cap` of the point and at most max_gap long has an end within
    // hypot(cap, max_gap / 2) of it: with no sample that near, the distance is `cap` anyway.
    const double radius = std::hypot(cap_, 0.5 * max_gap_) + 1e-9;
    const PointGrid2& points = reference_.grid();  // once: each call takes the reference's lock
    double sum = 0.0;
    for (const Eigen::Vector2d& p : current.points) {
      const Eigen::Vector2d q = pose * p;
      std::size_t k = 0;
      double squared = 0.0;
      double d = cap_;
      // The nearest sample's segments: a point between two samples of a wall is nearest to one
      // of them. Beyond a surface's end the end itself is the nearest.
      if (points.nearest(q, radius * radius, k, squared)) {
        const auto projected = project_onto_neighbour_segments(reference_.scan(), k, q, max_gap_);
        d = projected ? (projected->point - q).norm() : std::sqrt(squared);
      }
      sum += std::min(d, cap_);
    }
    return sum / static_cast<double>(current.points.size());
  }

 private:
  const Reference2D& reference_;
  double max_gap_, cap_;
};

/// refine_searched once the options and scans are checked.
Registration2DResult refine_checked(const Registration2DMethod& method, const Scan2D& current,
                                    const Reference2D& reference, const Registration2DOptions& o,
                                    const Pose2& searched) {
  Registration2DResult r = method.run(current, reference, o, searched);
  if (o.fine_fit_margin < 0.0) return r;
  const SurfaceDistance distance(reference, o.search_fill_gap, kSurfaceDistanceCap);
  const bool worse =
      !r.transform.matrix().allFinite() ||
      distance(current, r.transform) > distance(current, searched) + o.fine_fit_margin;
  if (worse) {
    r.transform = searched;
    r.search_pose_kept = true;
  }
  return r;
}

}  // namespace

Registration2DResult register_scans(const Scan2D& current, const Scan2D& reference,
                                    const Registration2DOptions& o, const Pose2& initial) {
  const Registration2DMethod& method = checked_method(current, reference, o);
  const Reference2D prepared(reference);
  if (!(o.search_window > 0.0)) return method.run(current, prepared, o, initial);
  const Pose2 searched = correlative_search(current, reference, initial, o.search_window,
                                            o.search_angle, o.search_resolution, o.search_fill_gap);
  return refine_checked(method, current, prepared, o, searched);
}

double surface_distance(const Scan2D& current, const Scan2D& reference, const Pose2& pose,
                        double max_gap, double cap) {
  return SurfaceDistance(Reference2D(reference), max_gap, cap)(current, pose);
}

Registration2DResult refine_searched(const Scan2D& current, const Scan2D& reference,
                                     const Registration2DOptions& o, const Pose2& searched) {
  return refine_searched(current, Reference2D(reference), o, searched);
}

Registration2DResult refine_searched(const Scan2D& current, const Reference2D& reference,
                                     const Registration2DOptions& o, const Pose2& searched) {
  return refine_checked(checked_method(current, reference.scan(), o), current, reference, o,
                        searched);
}

}  // namespace scanmatch
