// Verifying a 2D loop candidate, with its overlap and free-space checks (loop_verification2d.hpp).
#include "scanmatch/mapping/loop_verification2d.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <utility>

#include "scanmatch/core/error.hpp"
#include "scanmatch/geometry/point_grid2.hpp"
#include "scanmatch/registration/planar/correlative_search.hpp"
#include "scanmatch/registration/planar/reference2d.hpp"
#include "scanmatch/registration/planar/registration2d.hpp"

namespace scanmatch {
namespace {

bool finite_scan(const Scan2D& scan) {
  return std::all_of(scan.points.begin(), scan.points.end(),
                     [](const Eigen::Vector2d& p) { return p.allFinite(); });
}

// Reference points for the pairing: the distance to the nearest one within the pairing distance.
// The overlap checks query it for every point at every pose they test.
class PairingGrid {
 public:
  PairingGrid(const std::vector<Eigen::Vector2d>& points, double cell)
      : grid_(points, cell), squared_(cell * cell) {}
  /// Distance to the nearest point, or a negative value when none lies within `cell`.
  double nearest(const Eigen::Vector2d& p) const {
    std::size_t index = 0;
    double squared = 0.0;
    return grid_.nearest(p, squared_, index, squared) ? std::sqrt(squared) : -1.0;
  }

 private:
  PointGrid2 grid_;
  double squared_;
};

// The farthest return of a scan per bearing bin, in its own frame: what it saw to be free.
class RangeProfile {
 public:
  explicit RangeProfile(const std::vector<Eigen::Vector2d>& points) : ranges_(kBins, -1.0) {
    for (const Eigen::Vector2d& p : points) {
      double& r = ranges_[bin(p)];
      r = std::max(r, p.norm());
      farthest_ = std::max(farthest_, r);
    }
  }
  /// True when `p` (in this scan's frame) lies more than `margin` in front of the returns seen
  /// on both sides of its bearing (the nearest within kMaxGap bins each way, so that a beam
  /// spacing coarser than a bin does not hide the free space and an edge does not count).
  bool in_free_space(const Eigen::Vector2d& p, double margin) const {
    const double r = p.norm() + margin;
    if (!(r < farthest_)) return false;  // no return lies beyond it: spares the bearing
    const std::size_t b = bin(p);
    const double before = nearest_seen(b, kBins - 1), after = nearest_seen((b + 1) % kBins, 1);
    return before > r && after > r;
  }

 private:
  static constexpr std::size_t kBins = 720;  // 0.5 deg
  static constexpr std::size_t kMaxGap = 4;  // bins: a 1-degree laser missing one beam
  static std::size_t bin(const Eigen::Vector2d& p) {
    const double a = std::atan2(p.y(), p.x()) + M_PI;  // [0, 2 pi]
    return static_cast<std::size_t>(a / (2 * M_PI) * kBins) % kBins;
  }
  // The first return from bin `b` on, stepping by `step` (mod kBins); negative when none is near.
  double nearest_seen(std::size_t b, std::size_t step) const {
    for (std::size_t i = 0; i <= kMaxGap; ++i, b = (b + step) % kBins)
      if (ranges_[b] >= 0.0) return ranges_[b];
    return -1.0;
  }
  std::vector<double> ranges_;
  double farthest_ = -1.0;  // the farthest return of all
};

struct OverlapCheck {
  double paired_fraction = 0.0, error = 0.0, free_violations = 0.0, constraint = 0.0;
  /// Gauss-Newton Hessian of the paired points' point-to-line distances, for a motion of `from`
  /// in its own frame (x, y, theta): the pose graph's order and frame for an edge to `from`.
  Eigen::Matrix3d hessian = Eigen::Matrix3d::Zero();
};

// Unit normal of point j from its beam neighbours (zero where they are missing or far).
Eigen::Vector2d beam_normal(const Scan2D& scan, std::size_t j) {
  constexpr double kMaxGap = 0.3;  // m: farther neighbours lie on another surface
  const long prev = beam_neighbour(scan, j, -1), next = beam_neighbour(scan, j, 1);
  const Eigen::Vector2d& p = scan.points[j];
  const Eigen::Vector2d a =
      prev >= 0 && (scan.points[static_cast<std::size_t>(prev)] - p).norm() < kMaxGap
          ? scan.points[static_cast<std::size_t>(prev)]
          : p;
  const Eigen::Vector2d b =
      next >= 0 && (scan.points[static_cast<std::size_t>(next)] - p).norm() < kMaxGap
          ? scan.points[static_cast<std::size_t>(next)]
          : p;
  const Eigen::Vector2d t = b - a;
  if (t.norm() < 1e-6) return Eigen::Vector2d::Zero();
  return Eigen::Vector2d(-t.y(), t.x()).normalized();
}

// What a scan is checked against: its surfaces filled between samples (as the correlative search
// scores them: two scans sample a far wall metres apart, and sample-to-sample pairs would miss
// true loops), gridded for the nearest pair, and the free space it saw. Built once per scan and
// reused for every pose it is checked at. Joined scans each saw their free space from their own
// pose: the farthest return from the candidate's pose of a neighbour's point behind a wall says
// nothing about the space in front of it.
struct OverlapTarget {
  OverlapTarget(const Scan2D& onto, double pair_distance, double fill_gap)
      : OverlapTarget(onto, {{&onto, Pose2::Identity()}}, pair_distance, fill_gap) {}
  OverlapTarget(const Scan2D& onto, const std::vector<PosedScan2D>& views, double pair_distance,
                double fill_gap)
      : surfaces(filled_surfaces(onto, fill_gap, 0.5 * pair_distance), pair_distance) {
    for (const PosedScan2D& v : views) profiles.emplace_back(v.pose.inverse(), v.scan->points);
  }

  bool in_free_space(const Eigen::Vector2d& p, double margin) const {
    return std::any_of(profiles.begin(), profiles.end(), [&](const auto& view) {
      return view.second.in_free_space(view.first * p, margin);
    });
  }

  PairingGrid surfaces;                                  // the filled surfaces
  std::vector<std::pair<Pose2, RangeProfile>> profiles;  // into each view's frame, what it saw
};

// `from`'s points moved by `T` against `onto`'s surfaces and free space.
OverlapCheck check_overlap(const Scan2D& from, const OverlapTarget& onto, const Pose2& T,
                           double free_margin) {
  const PairingGrid& surfaces = onto.surfaces;
  OverlapCheck c;
  std::size_t paired = 0, free = 0;
  double sum = 0.0;
  Eigen::Matrix2d normals = Eigen::Matrix2d::Zero();
  for (std::size_t j = 0; j < from.points.size(); ++j) {
    const Eigen::Vector2d q = T * from.points[j];
    const double d = surfaces.nearest(q);
    if (d >= 0.0) {
      ++paired;
      sum += d;
      const Eigen::Vector2d n = beam_normal(from, j);
      normals += n * n.transpose();
      const Eigen::Vector2d& p = from.points[j];
      const Eigen::Vector3d J(n.x(), n.y(), n.x() * -p.y() + n.y() * p.x());
      c.hessian += J * J.transpose();
    } else if (onto.in_free_space(q, free_margin)) {
      ++free;
    }
  }
  const double n = static_cast<double>(std::max<std::size_t>(from.points.size(), 1));
  c.paired_fraction = static_cast<double>(paired) / n;
  c.free_violations = static_cast<double>(free) / n;
  c.error = paired > 0 ? sum / static_cast<double>(paired) : 1e9;
  const double trace = normals.trace();
  if (trace > 0.0) {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(normals / trace);
    c.constraint = eigen.eigenvalues()(0);  // ascending: the weaker direction
  }
  return c;
}

// check_overlap's pairing alone (how many of `from`'s points moved by `T` pair, and their
// distances' sum), without its free space and normals: the slid scans of the shift test leave
// most points unpaired, and looking each up in the free space of every joined view was most of
// that test.
struct Pairing {
  std::size_t paired = 0;
  double distance_sum = 0.0;
};
Pairing pair_onto(const Scan2D& from, const PairingGrid& onto, const Pose2& T) {
  Pairing out;
  for (const Eigen::Vector2d& p : from.points) {
    const double d = onto.nearest(T * p);
    if (d >= 0.0) {
      ++out.paired;
      out.distance_sum += d;
    }
  }
  return out;
}

double paired_share(const Scan2D& from, const OverlapTarget& onto, const Pose2& T) {
  return static_cast<double>(pair_onto(from, onto.surfaces, T).paired) /
         static_cast<double>(std::max<std::size_t>(from.points.size(), 1));
}

}  // namespace

double pairing_error_2d(const Scan2D& from, const Scan2D& onto, const Pose2& T,
                        double pair_distance) {
  if (from.points.empty() || onto.points.empty() || !finite_scan(from) || !finite_scan(onto) ||
      !T.matrix().allFinite())
    return -1.0;
  // The surfaces as OverlapTarget fills them; no free space is needed here.
  const PairingGrid surfaces(
      filled_surfaces(onto, Registration2DOptions{}.search_fill_gap, 0.5 * pair_distance),
      pair_distance);
  const Pairing p = pair_onto(from, surfaces, T);
  return p.paired > 0 ? p.distance_sum / static_cast<double>(p.paired) : -1.0;
}

struct LoopCurrent2D::Impl {
  Impl(const Scan2D& s, double pair, double gap)
      : scan(s), finite(finite_scan(s)), pair_distance(pair), fill_gap(gap) {}
  const OverlapTarget& overlap() const {
    std::call_once(
        built, [&] { target = std::make_unique<OverlapTarget>(scan, pair_distance, fill_gap); });
    return *target;
  }
  Scan2D scan;
  bool finite;
  double pair_distance, fill_gap;
  mutable std::once_flag built;
  mutable std::unique_ptr<OverlapTarget> target;
};

LoopCurrent2D::LoopCurrent2D(const Scan2D& scan, const LoopVerification2DOptions& options)
    : impl_(std::make_unique<Impl>(scan, options.pair_distance,
                                   Registration2DOptions{}.search_fill_gap)) {}
LoopCurrent2D::~LoopCurrent2D() = default;

struct LoopReference2D::Impl {
  Impl(const Scan2D& c, const std::vector<PosedScan2D>& neighbours, double pair, double gap)
      : candidate(c),
        candidate_finite(finite_scan(c)),
        joined(!neighbours.empty()),
        pair_distance(pair),
        fill_gap(gap),
        registration(joined ? submap : candidate) {
    if (!joined) return;
    submap = candidate;
    submap.circular = false;
    neighbour_scans.reserve(neighbours.size());  // `views` points into it
    views.push_back({&candidate, Pose2::Identity()});
    for (const PosedScan2D& n : neighbours) {
      if (!n.scan || !finite_scan(*n.scan) || !n.pose.matrix().allFinite()) continue;
      for (const Eigen::Vector2d& p : n.scan->points) submap.points.push_back(n.pose * p);
      neighbour_scans.push_back(*n.scan);
      views.push_back({&neighbour_scans.back(), n.pose});
    }
  }
  const Scan2D& reference() const { return joined ? submap : candidate; }
  const OverlapTarget& overlap() const {
    std::call_once(built, [&] {
      target = joined ? std::make_unique<OverlapTarget>(submap, views, pair_distance, fill_gap)
                      : std::make_unique<OverlapTarget>(candidate, pair_distance, fill_gap);
    });
    return *target;
  }
  Scan2D candidate;
  bool candidate_finite, joined;
  double pair_distance, fill_gap;
  Scan2D submap;                        // the candidate joined by its neighbours (`joined`)
  std::vector<Scan2D> neighbour_scans;  // the usable ones, as `views` sees them
  std::vector<PosedScan2D> views;       // each scan and its pose, for its free space (`joined`)
  Reference2D registration;             // of reference(), made on first use: declared after it
  mutable std::once_flag built;
  mutable std::unique_ptr<OverlapTarget> target;
};

LoopReference2D::LoopReference2D(const Scan2D& candidate,
                                 const std::vector<PosedScan2D>& candidate_neighbours,
                                 const LoopVerification2DOptions& options)
    : impl_(std::make_unique<Impl>(candidate, candidate_neighbours, options.pair_distance,
                                   Registration2DOptions{}.search_fill_gap)) {}
LoopReference2D::~LoopReference2D() = default;

LoopVerification2D verify_loop_2d(const Scan2D& current, const Scan2D& candidate,
                                  const Pose2& initial, const LoopVerification2DOptions& options,
                                  const std::vector<PosedScan2D>& candidate_neighbours,
                                  const std::optional<Pose2>& anchor) {
  return verify_loop_2d(LoopCurrent2D(current, options),
                        LoopReference2D(candidate, candidate_neighbours, options), initial, options,
                        anchor);
}

LoopVerification2D verify_loop_2d(const LoopCurrent2D& prepared_current,
                                  const LoopReference2D& prepared_candidate, const Pose2& initial,
                                  const LoopVerification2DOptions& options,
                                  const std::optional<Pose2>& anchor) {
  const LoopCurrent2D::Impl& here = prepared_current.impl();
  const LoopReference2D::Impl& there = prepared_candidate.impl();
  const Scan2D& current = here.scan;
  const Scan2D& candidate = there.candidate;
  const Pose2 slide_anchor = anchor.value_or(initial);
  LoopVerification2D out;
  out.transform = initial;
  const std::size_t min_points = std::max<std::size_t>(options.min_points, 3);
  if (current.points.size() < min_points || candidate.points.size() < min_points || !here.finite ||
      !there.candidate_finite || !initial.matrix().allFinite())
    return out;
  Registration2DOptions r;
  r.method = options.method;
  r.max_correspondence_distance = options.max_correspondence_distance;
  r.search_window = 0.0;  // searched here, so that a place nothing fits ends the check early
  const bool joined = there.joined;
  const Scan2D& reference_scan = there.reference();
  const Reference2D& registration_reference = there.registration;  // also for the sliding re-fit
  try {
    const CorrelativeMatch match = correlative_match(
        current, reference_scan, initial, options.search_window, options.search_angle,
        options.search_resolution, r.search_fill_gap, options.min_search_score);
    out.search_score = match.score;
    if (!match.found) return out;
    out.transform = refine_searched(current, registration_reference, r, match.pose).transform;
  } catch (const Error&) {
    return out;  // too few usable points for the method: not verifiable, so not a loop
  }
  if (!out.transform.matrix().allFinite()) return out;
  const OverlapTarget& reference = there.overlap();
  const OverlapTarget& current_target = here.overlap();
  // Fills out's checks at out.transform.
  struct Assessment {
    double forward_paired;  // the current scan's share paired onto the reference
    bool close;             // small error, nothing in the other's free space
    bool paired;            // enough of the points paired
  };
  const auto assess = [&]() {
    const OverlapCheck forward =
        check_overlap(current, reference, out.transform, options.free_margin);
    const OverlapCheck backward =
        check_overlap(candidate, current_target, out.transform.inverse(), options.free_margin);
    out.paired_fraction = joined ? forward.paired_fraction
                                 : std::min(forward.paired_fraction, backward.paired_fraction);
    // Against a submap the candidate alone may face away from the current scan and pair nothing:
    // then the way back has no error or constraint to report, only its free space.
    const bool backward_paired = !joined || backward.paired_fraction > 0.0;
    out.error = backward_paired ? std::max(forward.error, backward.error) : forward.error;
    out.free_violations = std::max(forward.free_violations, backward.free_violations);
    out.constraint =
        backward_paired ? std::min(forward.constraint, backward.constraint) : forward.constraint;
    out.hessian = forward.hessian;
    return Assessment{
        forward.paired_fraction,
        out.error <= options.max_error && out.free_violations <= options.max_free_violations,
        out.paired_fraction >= options.min_paired_fraction};
  };
  const Assessment first = assess();
  if (!first.close || !first.paired) return out;
  const double forward_paired = first.forward_paired;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(out.hessian.topLeftCorner<2, 2>());
  const Eigen::Vector2d weak = eigen.eigenvectors().col(0);
  bool determined = out.constraint >= options.min_constraint;
  if (determined && options.max_shifted_fraction > 0.0) {
    // Slid along the direction the match determines least, does the scan fit nearly as well?
    // Then the place is ambiguous there (a corridor, doors at even spacing).
    for (double shift : {-3.0, -2.0, -1.0, 1.0, 2.0, 3.0}) {
      const Pose2 shifted = out.transform * pose2(shift * weak.x(), shift * weak.y(), 0.0);
      out.shifted_fraction =
          std::max(out.shifted_fraction,
                   paired_share(current, reference, shifted) / std::max(forward_paired, 1e-9));
    }
    determined = out.shifted_fraction <= options.max_shifted_fraction;
  }
  if (determined || !options.accept_sliding) {
    out.accepted = determined;
    return out;
  }
  // Along the open direction the search stopped at any of the places that fit, perhaps a door
  // away; its weak direction is a little off the corridor's, so that slide leaks across. Fitted
  // again from the anchor's position along it, the match holds where the estimate puts it. The
  // first fit showed the same place; there the scans must still fit closely and not see into
  // each other's free space (the paired share may drop: sparse far samples pair only where the
  // two scans sampled alike, as at the first fit's alias).
  const Eigen::Vector2d axis = out.transform.rotation() * weak;
  Pose2 anchored = out.transform;
  anchored.translation() += axis * axis.dot(slide_anchor.translation() - anchored.translation());
  try {
    out.transform = refine_searched(current, registration_reference, r, anchored).transform;
  } catch (const Error&) {
    return out;
  }
  if (!out.transform.matrix().allFinite()) return out;
  const double shown_same_place = out.paired_fraction;
  const bool close = assess().close;
  out.paired_fraction = shown_same_place;
  if (!close) return out;
  out.accepted = true;
  out.sliding = true;
  out.slide_direction = weak;
  return out;
}

}  // namespace scanmatch
