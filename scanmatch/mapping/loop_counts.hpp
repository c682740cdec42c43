#pragma once
// The loop closures' counts (LoopClosure2DCounts, LoopClosure3DCounts: what counts() returns),
// each described once as a record (core/record.hpp): summary.json's "loop_closure" and Python's
// LoopClosure2D.counts / LoopClosure3D.counts take their keys from describe(). A new count is a
// member of its struct and one line here.

#include <concepts>
#include <type_traits>

#include "scanmatch/mapping/loop_closure2d.hpp"
#include "scanmatch/mapping/loop_closure3d.hpp"

namespace scanmatch {

namespace loop_counts_detail {
// The counts both loop closures keep (members of the same names).
template <typename Counts, typename Visitor>
void describe_shared(Counts& c, Visitor& v) {
  v("keyframes", c.keyframes, "keyframes: nodes of the pose graph");
  v("candidates", c.candidates, "candidate pairs proposed (after merging both sources)");
  v("verified", c.verified, "candidates that passed verification (loop edges added)");
  v("rejected_by_verification", c.rejected_by_verification, "candidates verification rejected");
  v("rejected_by_estimate", c.rejected_by_estimate,
    "verified but too far from the current estimate (max_correction): not added");
  v("rejected_as_outliers", c.outliers,
    "loop edges the graph judged outliers at its last optimization");
  v("optimizations", c.optimizations, "pose-graph optimizations");
}
}  // namespace loop_counts_detail

template <typename Counts, typename Visitor>
requires std::same_as<std::remove_const_t<Counts>, LoopClosure2DCounts>
void describe(Counts& c, Visitor& v) {
  loop_counts_detail::describe_shared(c, v);
  v("sliding", c.sliding,
    "verified loops accepted as sliding (they hold nothing along one direction)");
  v("open_odometry_edges", c.open_odometry_edges,
    "odometry edges whose step the scans leave open (open_step_spread)");
  v("rotation_open_odometry_edges", c.rotation_open_odometry_edges,
    "odometry edges whose rotation the scans leave open (rotation_open_ratio)");
  v("turned_at_open_rotation", c.turned_at_open_rotation,
    "verified loops the estimate check let through only by turning the keyframes after a "
    "rotation-open step");
  v("ruled_out_by_estimate", c.ruled_out_by_estimate,
    "place-database matches ruled out before verification (registration_reach); not candidates");
  v("max_error_m", c.max_error_m,
    "a loop's pairing error at most, at the last search (max_error, raised by "
    "max_error_per_floor), m");
  v("total_ms", c.total_ms, "wall time spent in add_scan() and finish(), ms");
}

template <typename Counts, typename Visitor>
requires std::same_as<std::remove_const_t<Counts>, LoopClosure3DCounts>
void describe(Counts& c, Visitor& v) {
  loop_counts_detail::describe_shared(c, v);
  v("prechecked_out", c.prechecked_out,
    "of rejected_by_verification, those its pre-check rejected before the fine stage");
  v("beyond_estimate_before_fine", c.beyond_estimate_before_fine,
    "of prechecked_out, those whose coarse pose lay beyond the estimate's reach");
  v("submaps_prepared", c.submaps_prepared,
    "keyframe submaps whose verification structures were built (the cache's misses)");
  v("ruled_out_by_estimate", c.ruled_out_by_estimate,
    "place-database matches ruled out before verification (registration_reach); not candidates");
  v("total_ms", c.total_ms, "wall time spent in add_frame() and finish(), ms");
}

}  // namespace scanmatch
