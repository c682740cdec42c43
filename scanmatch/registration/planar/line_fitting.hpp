#pragma once
// Lines fitted to a 2D scan along its beam order: what sparse-icp (and optionally pl-icp) match
// current points against, a straight surface rather than two samples of it.

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "scanmatch/core/scan2d.hpp"

namespace scanmatch {

/// A line fitted to a reference point and its beam-order neighbours: a point on it (their
/// centroid) and its unit normal, zero where too few neighbours lie on one straight surface.
/// `inward` points from the reference point along its surface where the point ends the surface
/// (no neighbour within the gap on one side), and is zero inside a surface.
struct FittedLine {
  Eigen::Vector2d point = Eigen::Vector2d::Zero(), normal = Eigen::Vector2d::Zero(),
                  inward = Eigen::Vector2d::Zero();
};

/// For each point, the least-squares line through the beam-order neighbours within `radius` of
/// it, walking outwards until a gap longer than `max_gap`. Two neighbouring samples 3 cm apart
/// with 1 % range noise give a line direction that is mostly noise; a fit over +-30 cm averages
/// it. Points whose neighbourhood bends (a corner: the smaller spread above a quarter of the
/// larger) get no line.
std::vector<FittedLine> fit_scan_lines(const Scan2D& scan, double radius, double max_gap);

/// The nearest point to `p` on the segments from reference point j to its beam-order neighbours,
/// and the unit normal of that segment (zero when j has no usable segment: the point is then j
/// itself). Segments longer than `max_length` span a gap, not a surface, and are not used.
struct SegmentProjection {
  Eigen::Vector2d point, normal;
};

/// Empty when j ends a surface and `p` lies beyond that end: such a point has no counterpart in
/// the reference (the edge of the range, an occlusion), and pairing it with the end would pull
/// the scan back along the surface, a bias that builds up along a corridor.
std::optional<SegmentProjection> project_onto_neighbour_segments(const Scan2D& reference,
                                                                 std::size_t j,
                                                                 const Eigen::Vector2d& p,
                                                                 double max_length);

}  // namespace scanmatch
