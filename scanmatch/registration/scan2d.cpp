#include "scanmatch/registration/scan2d.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <nanoflann.hpp>
#include <optional>

#include "scanmatch/core/error.hpp"
#include "scanmatch/features/angle_histogram.hpp"

namespace scanmatch {
namespace {

using Vec2 = Eigen::Vector2d;
using Points2 = std::vector<Vec2>;

constexpr std::size_t kMinPoints = 5;

struct Points2Adaptor {
  const Points2& points;
  std::size_t kdtree_get_point_count() const { return points.size(); }
  double kdtree_get_pt(std::size_t i, std::size_t dim) const {
    return points[i][static_cast<int>(dim)];
  }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }
};
using Tree2 =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, Points2Adaptor>,
                                        Points2Adaptor, 2, std::size_t>;

class NearestNeighbours2D {
 public:
  explicit NearestNeighbours2D(const Points2& points)
      : adaptor_{points}, tree_(2, adaptor_, nanoflann::KDTreeSingleIndexAdaptorParams(10)) {
    tree_.buildIndex();
  }
  /// Index of the nearest point and its squared distance.
  std::pair<std::size_t, double> nearest(const Vec2& q) const {
    std::size_t index = 0;
    double squared = 0.0;
    nanoflann::KNNResultSet<double, std::size_t> result(1);
    result.init(&index, &squared);
    tree_.findNeighbors(result, q.data(), nanoflann::SearchParams());
    return {index, squared};
  }

 private:
  Points2Adaptor adaptor_;
  Tree2 tree_;
};

/// The beams of a scan sorted by bearing from the sensor: where the path is lost, the reference
/// point nearest in bearing is where the reference scan would have seen a current point.
struct BearingIndex {
  explicit BearingIndex(const Points2& points);
  long nearest(const Vec2& p) const;  ///< index of the point nearest in bearing to p
  std::vector<std::pair<double, long>> sorted;
};

CorrespondencePath trace_path(const Points2& current, const Points2& reference, bool circular,
                              double max_distance, std::optional<BearingIndex>& bearings,
                              const PathRules& rules);

std::pair<std::size_t, double> brute_force_nearest(const Points2& points, const Vec2& q) {
  std::size_t best = 0;
  double best_squared = std::numeric_limits<double>::infinity();
  for (std::size_t j = 0; j < points.size(); ++j) {
    const double d = (points[j] - q).squaredNorm();
    if (d < best_squared) {
      best_squared = d;
      best = j;
    }
  }
  return {best, best_squared};
}

Points2 transformed(const Points2& points, const Pose2& T) {
  Points2 out(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) out[i] = T * points[i];
  return out;
}

/// Index of the beam-order neighbour of j (step -1 or +1) in a scan of m points, wrapping on a
/// circular scan; -1 past the ends of an open one.
long beam_neighbour(long m, bool circular, long j, long step) {
  long k = j + step;
  if (circular) k = (k + m) % m;
  return k < 0 || k >= m ? -1 : k;
}
long beam_neighbour(const Scan2D& scan, std::size_t j, long step) {
  return beam_neighbour(static_cast<long>(scan.points.size()), scan.circular, static_cast<long>(j),
                        step);
}

Vec2 centroid(const Points2& points) {
  Vec2 c = Vec2::Zero();
  for (const Vec2& p : points) c += p;
  return points.empty() ? c : Vec2(c / static_cast<double>(points.size()));
}

bool small_step(const Pose2& step, double tolerance) {
  return step.translation().norm() < tolerance && std::abs(pose2_angle(step)) < tolerance;
}

/// Unit normals of a scan from its beam-order neighbours; zero where a point has no neighbour
/// within `max_gap` on either side (an isolated return has no surface direction).
Points2 scan_normals(const Points2& points, bool circular, double max_gap) {
  const long n = static_cast<long>(points.size());
  Points2 normals(points.size(), Vec2::Zero());
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

/// A line fitted to a reference point and its beam-order neighbours: a point on it (their
/// centroid) and its unit normal, zero where too few neighbours lie on one straight surface.
/// `inward` points from the reference point along its surface where the point ends the surface
/// (no neighbour within the gap on one side), and is zero inside a surface.
struct FittedLine {
  Vec2 point = Vec2::Zero(), normal = Vec2::Zero(), inward = Vec2::Zero();
};

/// For each point, the least-squares line through the beam-order neighbours within `radius` of
/// it, walking outwards until a gap longer than `max_gap`. Two neighbouring samples 3 cm apart
/// with 1 % range noise give a line direction that is mostly noise; a fit over +-30 cm averages
/// it.
/// Points whose neighbourhood bends (a corner: the smaller spread above a quarter of the larger)
/// get no line.
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

/// A point of the current scan against a line of the reference: the point (current frame), a
/// point of the line and its unit normal (reference frame), and the distance at the current pose.
struct LinePair {
  Vec2 point, on_line, normal;
  double distance;
};

/// Keeps the `fraction` of pairs nearest to their lines (at least three).
void keep_nearest_fraction(std::vector<LinePair>& pairs, double fraction) {
  const std::size_t keep = std::max<std::size_t>(
      3, static_cast<std::size_t>(std::ceil(fraction * static_cast<double>(pairs.size()))));
  if (keep >= pairs.size()) return;
  std::nth_element(pairs.begin(), pairs.begin() + static_cast<std::ptrdiff_t>(keep), pairs.end(),
                   [](const LinePair& a, const LinePair& b) { return a.distance < b.distance; });
  pairs.resize(keep);
}

/// Adds one point-to-line pair to the normal equations of the unknowns x = (tx, ty, c, s): the
/// residual is n . (M x - q) with M = [1 0 px -py; 0 1 py px].
void add_line_pair(const Vec2& p, const Vec2& on_line, const Vec2& normal, Eigen::Matrix4d& H,
                   Eigen::Vector4d& g) {
  Eigen::Matrix<double, 2, 4> M;
  M << 1, 0, p.x(), -p.y(), 0, 1, p.y(), p.x();
  const Eigen::Matrix<double, 1, 4> a = normal.transpose() * M;
  H += a.transpose() * a;
  g += a.transpose() * normal.dot(on_line);
}

Pose2 solve_line_normal_equations(const Eigen::Matrix4d& H, const Eigen::Vector4d& g);

/// Censi's closed-form step on the pairs; their mean distance goes to `mean_distance`. A faint
/// pull towards the current pose (1e-6 of the pairs' weight) keeps a degenerate set solvable (a
/// corridor's walls are all parallel): along what the pairs leave free the pose stays where it
/// is, and elsewhere the pull changes nothing measurable.
Pose2 solve_line_pairs(const std::vector<LinePair>& pairs, const Pose2& current,
                       double& mean_distance) {
  Eigen::Matrix4d H = Eigen::Matrix4d::Zero();
  Eigen::Vector4d g = Eigen::Vector4d::Zero();
  double sum = 0.0;
  for (const LinePair& pair : pairs) {
    add_line_pair(pair.point, pair.on_line, pair.normal, H, g);
    sum += pair.distance;
  }
  mean_distance = sum / static_cast<double>(pairs.size());
  const double pull = 1e-6 * static_cast<double>(pairs.size());
  const Eigen::Vector4d x(current.translation().x(), current.translation().y(),
                          current.linear()(0, 0), current.linear()(1, 0));
  H.diagonal().array() += pull;
  g += pull * x;
  return solve_line_normal_equations(H, g);
}

struct Pairs {
  Points2 from, to;
  double distance_sum = 0.0;
  void clear() {
    from.clear();
    to.clear();
    distance_sum = 0.0;
  }
};

// One point-to-point ICP: nearest neighbours (brute force or k-d tree), optional normal
// rejection, SVD step.
Registration2DResult point_to_point_icp(const Scan2D& current, const Scan2D& reference,
                                        const Registration2DOptions& o, const Pose2& initial,
                                        bool use_tree, bool normal_rejection) {
  std::optional<NearestNeighbours2D> tree;
  if (use_tree) tree.emplace(reference.points);
  Points2 reference_normals, current_normals;
  if (normal_rejection) {
    const double gap = 3 * o.max_correspondence_distance;
    reference_normals = scan_normals(reference.points, reference.circular, gap);
    current_normals = scan_normals(current.points, current.circular, gap);
  }
  const double max_squared = o.max_correspondence_distance * o.max_correspondence_distance;
  const double min_cos = std::cos(o.normal_angle);
  Registration2DResult r;
  r.transform = initial;
  Pairs pairs;
  for (r.iterations = 1; r.iterations <= o.max_iterations; ++r.iterations) {
    pairs.clear();
    const Eigen::Matrix2d R = r.transform.linear();
    for (std::size_t i = 0; i < current.points.size(); ++i) {
      const Vec2 p = r.transform * current.points[i];
      const auto [j, squared] =
          use_tree ? tree->nearest(p) : brute_force_nearest(reference.points, p);
      if (squared > max_squared) continue;
      if (normal_rejection) {
        const Vec2& nr = reference_normals[j];
        const Vec2 nc = R * current_normals[i];
        if (nr.isZero() || nc.isZero() || std::abs(nr.dot(nc)) < min_cos) continue;
      }
      pairs.from.push_back(current.points[i]);
      pairs.to.push_back(reference.points[j]);
      pairs.distance_sum += std::sqrt(squared);
    }
    r.pairs = pairs.from.size();
    if (r.pairs < 3) break;
    const Pose2 next = align_svd(pairs.from, pairs.to);
    const Pose2 step = next * r.transform.inverse();
    r.transform = next;
    r.error = pairs.distance_sum / static_cast<double>(r.pairs);
    if (small_step(step, o.tolerance)) {
      r.converged = true;
      break;
    }
  }
  r.iterations = std::min(r.iterations, o.max_iterations);
  return r;
}

// Censi's PL-ICP: each point against the line through its nearest reference point and the nearer
// of that point's two beam-order neighbours; the worst pairs beyond keep_fraction are dropped.
Registration2DResult point_to_line_icp(const Scan2D& current, const Scan2D& reference,
                                       const Registration2DOptions& o, const Pose2& initial) {
  const NearestNeighbours2D tree(reference.points);
  const double max_squared = o.max_correspondence_distance * o.max_correspondence_distance;
  std::vector<FittedLine> lines;
  if (o.pl_line_radius > 0.0)
    lines = fit_scan_lines(reference, o.pl_line_radius, o.max_correspondence_distance);
  std::vector<LinePair> pairs;
  Registration2DResult r;
  r.transform = initial;
  for (r.iterations = 1; r.iterations <= o.max_iterations; ++r.iterations) {
    pairs.clear();
    for (const Vec2& point : current.points) {
      const Vec2 p = r.transform * point;
      const auto [j, squared] = tree.nearest(p);
      if (squared > max_squared) continue;
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
    keep_nearest_fraction(pairs, o.keep_fraction);
    r.pairs = pairs.size();
    const Pose2 next = solve_line_pairs(pairs, r.transform, r.error);
    const Pose2 step = next * r.transform.inverse();
    r.transform = next;
    if (small_step(step, o.tolerance)) {
      r.converged = true;
      break;
    }
  }
  r.iterations = std::min(r.iterations, o.max_iterations);
  return r;
}

/// The nearest point to `p` on the segments from reference point j to its beam-order neighbours,
/// and the unit normal of that segment (zero when j has no usable segment: the point is then j
/// itself). Segments longer than `max_length` span a gap, not a surface, and are not used.
struct SegmentProjection {
  Vec2 point, normal;
};

/// Empty when j ends a surface and `p` lies beyond that end: such a point has no counterpart in
/// the reference (the edge of the range, an occlusion), and pairing it with the end would pull
/// the scan back along the surface, a bias that builds up along a corridor.
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

Registration2DResult sparse_icp(const Scan2D& current, const Scan2D& reference,
                                const Registration2DOptions& o, const Pose2& initial, bool coarse) {
  Registration2DResult r;
  r.transform = initial;
  if (coarse && (o.coarse_rotation || o.coarse_translation))
    r.transform = coarse_alignment_2d(transformed(current.points, initial), reference.points,
                                      o.histogram_bin, o.histogram_max_rotation, o.coarse_rotation,
                                      o.coarse_translation, o.histogram_min_segment) *
                  initial;
  Pairs pairs;
  std::vector<LinePair> line_pairs;
  const bool point_to_line = o.sparse_step == "point-to-line";
  std::optional<BearingIndex> bearings;
  std::vector<FittedLine> lines;
  if (point_to_line && o.sparse_line_radius > 0.0)
    lines = fit_scan_lines(reference, o.sparse_line_radius, o.max_correspondence_distance);
  for (r.iterations = 1; r.iterations <= o.max_iterations; ++r.iterations) {
    const Points2 moved = transformed(current.points, r.transform);
    const CorrespondencePath path =
        trace_path(moved, reference.points, reference.circular, o.max_correspondence_distance,
                   bearings, o.path_rules);
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
      if (o.sparse_keep_fraction < 1.0) keep_nearest_fraction(line_pairs, o.sparse_keep_fraction);
      r.pairs = line_pairs.size();
      next = solve_line_pairs(line_pairs, r.transform, r.error);
    } else {
      r.pairs = pairs.from.size();
      next = align_svd(pairs.from, pairs.to);
      r.error = pairs.distance_sum / static_cast<double>(r.pairs);
    }
    const Pose2 step = next * r.transform.inverse();
    r.transform = next;
    if (small_step(step, std::max(o.tolerance, o.sparse_tolerance))) {
      r.converged = true;
      break;
    }
  }
  r.iterations = std::min(r.iterations, o.max_iterations);
  return r;
}

void check_scan(const Scan2D& scan, const char* which) {
  if (scan.points.size() < kMinPoints)
    throw Error(std::string("2D registration: the ") + which + " scan has " +
                std::to_string(scan.points.size()) + " valid points, at least " +
                std::to_string(kMinPoints) + " are needed");
  for (const Vec2& p : scan.points)
    if (!p.allFinite())
      throw Error(std::string("2D registration: the ") + which + " scan has a non-finite point");
}

}  // namespace

Pose2 pose2(double x, double y, double theta) {
  Pose2 T = Pose2::Identity();
  T.linear() = Eigen::Rotation2Dd(theta).toRotationMatrix();
  T.translation() = Vec2(x, y);
  return T;
}

Pose2 pose2(const Eigen::Vector3d& xytheta) {
  return pose2(xytheta.x(), xytheta.y(), xytheta.z());
}

double pose2_angle(const Pose2& T) {
  return std::atan2(T.linear()(1, 0), T.linear()(0, 0));
}

Scan2D scan_from_laser(const LaserScan2D& scan, double min_range, double miss_range,
                       double rotation_period) {
  Scan2D out;
  const double max_range = scan.max_range;
  const double free_range = miss_range > 0.0 ? miss_range : max_range;
  out.points.reserve(scan.ranges.size());
  for (std::size_t i = 0; i < scan.ranges.size(); ++i) {
    const double range = scan.ranges[i];
    const double angle = scan.angle_min + static_cast<double>(i) * scan.angle_increment;
    const Vec2 direction(std::cos(angle), std::sin(angle));
    if (!std::isfinite(range)) continue;
    if (range >= max_range) {
      out.misses.push_back(free_range * direction);
      continue;
    }
    if (range <= min_range) continue;
    out.points.push_back(range * direction);
    if (rotation_period > 0.0)
      out.times.push_back(rotation_period * static_cast<double>(i) *
                          std::abs(scan.angle_increment) / (2 * M_PI));
  }
  const double span = static_cast<double>(scan.ranges.size()) * std::abs(scan.angle_increment);
  out.circular = span > 2 * M_PI - 1.5 * std::abs(scan.angle_increment);
  return out;
}

const std::vector<std::string>& registration_2d_method_names() {
  static const std::vector<std::string> names = {"sparse-icp", "icp", "icp-kdtree", "pl-icp",
                                                 "normal-icp"};
  return names;
}

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

void check_registration_2d_method(const std::string& method) {
  const auto& names = registration_2d_method_names();
  if (std::find(names.begin(), names.end(), method) != names.end()) return;
  std::string valid;
  for (const std::string& name : names) valid += (valid.empty() ? "" : ", ") + name;
  throw Error("unknown 2D registration method '" + method + "' (" + valid + ")");
}

Pose2 align_svd(const Points2& from, const Points2& to) {
  if (from.size() != to.size() || from.size() < 2)
    throw Error("align_svd: needs two or more pairs of points");
  const Vec2 mu_p = centroid(from), mu_q = centroid(to);
  Eigen::Matrix2d W = Eigen::Matrix2d::Zero();
  for (std::size_t i = 0; i < from.size(); ++i) W += (to[i] - mu_q) * (from[i] - mu_p).transpose();
  const Eigen::JacobiSVD<Eigen::Matrix2d> svd(W, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix2d U = svd.matrixU();
  const Eigen::Matrix2d V = svd.matrixV();
  if ((U * V.transpose()).determinant() < 0) U.col(1) *= -1;  // a reflection is not a rotation
  Pose2 T = Pose2::Identity();
  T.linear() = U * V.transpose();
  T.translation() = mu_q - T.linear() * mu_p;
  return T;
}

Pose2 coarse_alignment_2d(const Points2& current, const Points2& reference, double bin_width,
                          double max_rotation, bool rotation, bool translation,
                          double min_segment) {
  Pose2 correction = Pose2::Identity();
  if (rotation) {
    const double angle =
        histogram_rotation(angle_histogram(current, bin_width, 0.5, min_segment),
                           angle_histogram(reference, bin_width, 0.5, min_segment), max_rotation);
    correction.linear() = Eigen::Rotation2Dd(angle).toRotationMatrix();
  }
  if (translation)
    correction.translation() = centroid(reference) - correction.linear() * centroid(current);
  return correction;
}

CorrespondencePath correspondence_path(const Points2& current, const Points2& reference,
                                       bool circular, double max_distance, const PathRules& rules) {
  std::optional<BearingIndex> bearings;
  return trace_path(current, reference, circular, max_distance, bearings, rules);
}

namespace {
BearingIndex::BearingIndex(const Points2& points) {
  sorted.reserve(points.size());
  for (std::size_t j = 0; j < points.size(); ++j)
    sorted.emplace_back(std::atan2(points[j].y(), points[j].x()), static_cast<long>(j));
  std::sort(sorted.begin(), sorted.end());
}

long BearingIndex::nearest(const Vec2& p) const {
  const double bearing = std::atan2(p.y(), p.x());
  auto after = std::lower_bound(sorted.begin(), sorted.end(), std::make_pair(bearing, -1L));
  if (after == sorted.end()) after = sorted.begin();  // wraps past +pi
  const auto before = after == sorted.begin() ? sorted.end() - 1 : after - 1;
  const auto gap = [&](double b) { return std::abs(std::remainder(b - bearing, 2 * M_PI)); };
  return gap(before->first) < gap(after->first) ? before->second : after->second;
}

CorrespondencePath trace_path(const Points2& current, const Points2& reference, bool circular,
                              double max_distance, std::optional<BearingIndex>& bearings,
                              const PathRules& rules) {
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
        if (!bearings) bearings.emplace(reference);  // built once, when first needed
        const long seed = bearings->nearest(current[static_cast<std::size_t>(i)]);
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
}  // namespace

Pose2 solve_point_to_line(const Points2& points, const Points2& line_points,
                          const Points2& normals) {
  if (points.size() < 3 || line_points.size() != points.size() || normals.size() != points.size())
    throw Error("point-to-line step: needs three or more pairs with a normal each");
  Eigen::Matrix4d H = Eigen::Matrix4d::Zero();
  Eigen::Vector4d g = Eigen::Vector4d::Zero();
  for (std::size_t i = 0; i < points.size(); ++i)
    add_line_pair(points[i], line_points[i], normals[i], H, g);
  return solve_line_normal_equations(H, g);
}

namespace {
Pose2 solve_line_normal_equations(const Eigen::Matrix4d& H, const Eigen::Vector4d& g) {
  // Eliminate t: for fixed v = (c, s), t = A^-1 (g_t - B v); the cost in v is v'Sv - 2h'v + k.
  const Eigen::Matrix2d A = H.topLeftCorner<2, 2>(), B = H.topRightCorner<2, 2>(),
                        D = H.bottomRightCorner<2, 2>();
  const Eigen::Vector2d gt = g.head<2>(), gv = g.tail<2>();
  if (std::abs(A.determinant()) < 1e-12)
    throw Error("point-to-line step: translation is unconstrained");
  const Eigen::Matrix2d Ainv = A.inverse();
  const Eigen::Matrix2d S = D - B.transpose() * Ainv * B;
  const Eigen::Vector2d h = gv - B.transpose() * Ainv * gt;
  // Minimise v'Sv - 2h'v subject to |v| = 1: (S + l I) v = h with |v| = 1, i.e.
  // |adj(S + l I) h|^2 = det(S + l I)^2, a quartic in l.
  const double a = S(0, 0), b = S(0, 1), d = S(1, 1);
  // adj(S + l I) h = (p0 + l h0, p1 + l h1) with p = adj(S) h.
  const double p0 = d * h.x() - b * h.y(), p1 = a * h.y() - b * h.x();
  // det(S + l I) = l^2 + (a + d) l + (a d - b^2).
  const double c1 = a + d, c0 = a * d - b * b;
  // det^2 - |adj h|^2 = 0, coefficients from l^4 down to l^0.
  Eigen::Matrix<double, 5, 1> poly;
  poly << 1.0, 2 * c1, c1 * c1 + 2 * c0 - h.squaredNorm(),
      2 * c1 * c0 - 2 * (p0 * h.x() + p1 * h.y()), c0 * c0 - p0 * p0 - p1 * p1;
  Eigen::Matrix4d companion = Eigen::Matrix4d::Zero();
  for (int k = 0; k < 4; ++k) companion(0, k) = -poly(k + 1) / poly(0);
  companion.bottomLeftCorner<3, 3>() = Eigen::Matrix3d::Identity();
  const Eigen::EigenSolver<Eigen::Matrix4d> roots(companion, false);
  Vec2 best_v(1, 0);
  double best_cost = std::numeric_limits<double>::infinity();
  const auto consider = [&](Vec2 v) {
    if (!v.allFinite() || v.norm() < 1e-12) return;
    v.normalize();
    const double cost = v.dot(S * v) - 2 * h.dot(v);
    if (cost < best_cost) {
      best_cost = cost;
      best_v = v;
    }
  };
  for (int k = 0; k < 4; ++k) {
    const std::complex<double> lambda = roots.eigenvalues()(k);
    if (std::abs(lambda.imag()) > 1e-6 * std::max(1.0, std::abs(lambda.real()))) continue;
    const Eigen::Matrix2d K = S + lambda.real() * Eigen::Matrix2d::Identity();
    if (std::abs(K.determinant()) < 1e-15) continue;
    consider(K.inverse() * h);
  }
  // Should rounding lose every real root, the unconstrained direction still gives a rotation.
  consider(h);
  Pose2 T = Pose2::Identity();
  T.linear() << best_v.x(), -best_v.y(), best_v.y(), best_v.x();
  T.translation() = Ainv * (gt - B * best_v);
  return T;
}
}  // namespace

Registration2DResult register_scans(const Scan2D& current, const Scan2D& reference,
                                    const Registration2DOptions& o, const Pose2& initial) {
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
  check_scan(current, "current");
  check_scan(reference, "reference");
  Pose2 start = initial;
  const bool searched = o.search_window > 0.0;
  if (searched)
    start = correlative_search(current, reference, initial, o.search_window, o.search_angle,
                               o.search_resolution);
  if (o.method == "sparse-icp") return sparse_icp(current, reference, o, start, !searched);
  if (o.method == "pl-icp") return point_to_line_icp(current, reference, o, start);
  return point_to_point_icp(current, reference, o, start, o.method != "icp",
                            o.method == "normal-icp");
}

}  // namespace scanmatch
