#pragma once
// Loop closure's options (2D and 3D: pose graph, place descriptors, verification), described
// once (the protocol: fields.hpp).
#include "scanmatch/config/fields.hpp"
#include "scanmatch/features/place_descriptor.hpp"
#include "scanmatch/mapping/loop_candidates.hpp"
#include "scanmatch/mapping/loop_closure2d.hpp"
#include "scanmatch/mapping/loop_closure3d.hpp"
#include "scanmatch/mapping/pose_graph.hpp"

namespace scanmatch {

inline const char* enum_name(LoopKernel kernel) {
  switch (kernel) {
    case LoopKernel::kNone:
      return "none";
    case LoopKernel::kHuber:
      return "huber";
    case LoopKernel::kCauchy:
      return "cauchy";
  }
  return "none";
}
inline void enum_from_name(const std::string& name, LoopKernel& kernel) {
  if (name == "none")
    kernel = LoopKernel::kNone;
  else if (name == "huber")
    kernel = LoopKernel::kHuber;
  else if (name == "cauchy")
    kernel = LoopKernel::kCauchy;
  else
    throw Error("unknown pose graph kernel '" + name + "' (none, huber, cauchy)");
}

template <typename Visitor>
void describe(PoseGraphConfig& g, Visitor& v) {
  v("loop_kernel", g.loop_kernel, nullptr, "Robust kernel of loop edges: none, huber, cauchy");
  v("loop_kernel_scale", g.loop_kernel_scale, nullptr,
    "Where the loop kernel starts, in standard deviations");
  v("odometry_kernel", g.odometry_kernel, nullptr,
    "Robust kernel of odometry edges: none, huber, cauchy");
  v("odometry_kernel_scale", g.odometry_kernel_scale, nullptr,
    "Where the odometry kernel starts, in standard deviations");
  v("outlier_chi2_2d", g.outlier_chi2_2d, nullptr,
    "Chi-square above which a 2D loop is an outlier");
  v("outlier_chi2_3d", g.outlier_chi2_3d, nullptr,
    "Chi-square above which a 3D loop is an outlier");
  v("drop_outliers", g.drop_outliers, nullptr, "Re-solve without the outlier loops");
  v("max_iterations", g.max_iterations, nullptr, "Levenberg-Marquardt iterations per solve");
}

// Spliced flat into both loop closures' objects (not nested), where their keys always stood.
template <typename Visitor>
void describe(LoopCandidateOptions& o, Visitor& v) {
  v("proximity_radius", o.proximity_radius, nullptr,
    "Candidates within this distance in the current estimate, m");
  v("max_proximity_candidates", o.max_proximity_candidates, nullptr,
    "Pose-proximity candidates per keyframe, at most");
  v("max_descriptor_distance", o.max_descriptor_distance, nullptr,
    "Place-database candidates below this descriptor distance");
  v("max_descriptor_candidates", o.max_descriptor_candidates, nullptr,
    "Place-database candidates per keyframe, at most");
}

template <typename Visitor>
void describe(LoopVerification2DOptions& o, Visitor& v) {
  v("method", o.method, nullptr, "Registration method of the verification's fine stage");
  v("search_window", o.search_window, nullptr, "Correlative search, +- m around the candidate");
  v("search_angle", o.search_angle, nullptr, "Correlative search, +- rad");
  v("search_resolution", o.search_resolution, nullptr, "Correlative search cell size, m");
  v("min_search_score", o.min_search_score, nullptr,
    "Reject where no pose of the search scores this share of its best (0: search through)");
  v("max_correspondence_distance", o.max_correspondence_distance, nullptr,
    "Fine stage's correspondence distance, m");
  v("pair_distance", o.pair_distance, nullptr, "A point is paired within this distance, m");
  v("min_paired_fraction", o.min_paired_fraction, nullptr,
    "Share of each scan's points that must be paired");
  v("max_error", o.max_error, nullptr, "Mean distance of the paired points, at most, m");
  v("free_margin", o.free_margin, nullptr,
    "A point this far (m) in front of the other scan's return lies in its free space");
  v("max_free_violations", o.max_free_violations, nullptr,
    "Share of points in the other scan's free space, at most");
  v("min_constraint", o.min_constraint, nullptr,
    "The weaker direction's share of the paired normals, at least (corridors fail)");
  v("min_points", o.min_points, nullptr, "Points each scan needs to be verified");
  v("max_shifted_fraction", o.max_shifted_fraction, nullptr,
    "reject when slid 1-3 m along the weak direction keeps more of the pairs (0: off)");
  v("accept_sliding", o.accept_sliding, nullptr,
    "Accept a fitting match that leaves one direction open, holding the rest only");
}

template <typename Visitor>
void describe(PlaceDescriptorOptions& o, Visitor& v) {
  v("rings", o.rings, nullptr, "Place descriptor: rings of range");
  v("sectors", o.sectors, nullptr, "Place descriptor: sectors of bearing");
  v("max_range", o.max_range, nullptr, "Place descriptor: range of the outer ring, m");
  v("height_offset", o.height_offset, nullptr, "Place descriptor: m added to z (sensor height)");
}

template <typename Visitor>
void describe(PlaceDescriptor2DOptions& o, Visitor& v) {
  v("rings", o.rings, nullptr, "Place descriptor: rings of range");
  v("sectors", o.sectors, nullptr, "Place descriptor: sectors of bearing");
  v("max_range", o.max_range, nullptr, "Place descriptor: range of the outer ring, m");
}

template <typename Visitor>
void describe(LoopVerification3DOptions& o, Visitor& v) {
  v("coarse_method", o.coarse_method, nullptr, "Registration method of the coarse stage");
  v("coarse_resolution", o.coarse_resolution, nullptr, "Coarse stage's voxel grid, m");
  v("coarse_source_voxel", o.coarse_source_voxel, nullptr,
    "Coarse stage: the current submap downsampled to this voxel, m (0: every point)");
  v("fine_reach", o.fine_reach, nullptr,
    "A coarse pose farther than the estimate's allowance plus this (m) skips the fine stage");
  v("fine_method", o.fine_method, nullptr, "Registration method of the fine stage");
  v("fine_max_correspondence_distance", o.fine_max_correspondence_distance, nullptr,
    "Fine stage's correspondence distance, m");
  v("max_iterations", o.max_iterations, nullptr, "Iterations of each stage");
  v("pair_distance", o.pair_distance, nullptr, "A point pairs with the nearest within this, m");
  v("plane_distance", o.plane_distance, nullptr,
    "A paired point agrees within this distance of the tangent plane, m");
  v("min_overlap", o.min_overlap, nullptr, "Share of each submap that must agree");
  v("max_error", o.max_error, nullptr, "Mean plane distance of the agreeing points, at most, m");
  v("min_constraint", o.min_constraint, nullptr,
    "The weakest translation direction's share of the normals, at least");
  v("min_points", o.min_points, nullptr, "Points each submap needs to be verified");
}

template <typename Visitor>
void describe(LoopClosure3DOptions& o, Visitor& v) {
  v("keyframe_distance", o.keyframe_distance, nullptr, "New loop keyframe after this many m");
  v("keyframe_angle", o.keyframe_angle, nullptr, "New loop keyframe after this many rad");
  v("submap_frames", o.submap_frames, nullptr, "Frames in a keyframe's submap");
  v("submap_voxel", o.submap_voxel, nullptr, "Submap voxel, m");
  v("max_submap_points", o.max_submap_points, nullptr, "Submap points, at most");
  v("odometry_sigma_translation", o.odometry_sigma_translation, nullptr,
    "Odometry edge standard deviation, m");
  v("odometry_sigma_rotation", o.odometry_sigma_rotation, nullptr,
    "Odometry edge standard deviation, rad");
  v("loop_sigma_translation", o.loop_sigma_translation, nullptr,
    "Loop edge: the best translation direction's standard deviation, m");
  v("loop_sigma_rotation", o.loop_sigma_rotation, nullptr,
    "Loop edge: the best rotation direction's standard deviation, at least, rad");
  v("skip_recent", o.skip_recent, nullptr, "Newest keyframes that are never candidates");
  describe(o.candidates, v);  // flat: its keys stand here in the loop closure's object
  v("descriptor_matches", o.descriptor_matches, nullptr,
    "Place-database matches looked at per keyframe");
  v("max_correction", o.max_correction, nullptr,
    "A verified loop may move the estimate by this many m ...");
  v("max_correction_per_m", o.max_correction_per_m, nullptr,
    "... plus this share of the path between the two keyframes");
  v("registration_reach", o.registration_reach, nullptr,
    "How far verification can move a candidate, m");
  v("search_every", o.search_every, nullptr, "Look for loops at every this-many keyframes");
  v("keyframes_between_loops", o.keyframes_between_loops, nullptr,
    "Keyframes without a search after one that added a loop");
  v("verification_memory_mb", o.verification_memory_mb, nullptr,
    "MB of submap structures (trees, covariances, voxel maps) kept between verifications");
  v.nested("verification", o.verification);
  v.nested("descriptor", o.descriptor);
  v.nested("graph", o.graph);
}

template <typename Visitor>
void describe(LoopClosure2DOptions& o, Visitor& v) {
  v("keyframe_distance", o.keyframe_distance, nullptr, "New loop keyframe after this many m");
  v("keyframe_angle", o.keyframe_angle, nullptr, "New loop keyframe after this many rad");
  v("odometry_sigma_xy", o.odometry_sigma_xy, nullptr, "Odometry edge standard deviation, m");
  v("odometry_sigma_theta", o.odometry_sigma_theta, nullptr,
    "Odometry edge standard deviation, rad");
  v("odometry_spread_window", o.odometry_spread_window, nullptr,
    "Odometry edges widen where translations within this window (m) fit as well (0: fixed)");
  v("odometry_spread_margin", o.odometry_spread_margin, nullptr,
    "... within this share of the points of the best fit");
  v("odometry_spread_normal", o.odometry_spread_normal, nullptr,
    "... by their spread beyond this, m");
  v("open_steps_are_keyframes", o.open_steps_are_keyframes, nullptr,
    "A scan whose step is open becomes a keyframe however little the odometry moved");
  v("open_step_spread", o.open_step_spread, nullptr, "... open: its spread is at least this, m");
  v("rotation_open_ratio", o.rotation_open_ratio, nullptr,
    "A keyframe step whose rotations 10-90 deg off fit this share of its own is rotation-open "
    "(0: off)");
  v("rotation_open_sigma_theta", o.rotation_open_sigma_theta, nullptr,
    "... its odometry edge's rotation standard deviation, rad");
  v("rotation_open_min_turn", o.rotation_open_min_turn, nullptr,
    "... tested where the step turns at least this much (and where the odometry's fit was weak), "
    "rad");
  v("unfit_step_information", o.unfit_step_information, nullptr,
    "share of its information a keyframe step keeps where the odometry could not register a "
    "scan of it (1: all)");
  v("loop_sigma_xy", o.loop_sigma_xy, nullptr, "Loop edge standard deviation, m");
  v("loop_sigma_theta", o.loop_sigma_theta, nullptr, "Loop edge standard deviation, rad");
  v("skip_recent", o.skip_recent, nullptr, "Newest keyframes that are never candidates");
  v("submap_keyframes", o.submap_keyframes, nullptr,
    "the candidate's neighbours within this many keyframes join it for verification");
  v("max_error_per_floor", o.max_error_per_floor, nullptr,
    "A loop's pairing error may reach this many times the run's keyframe steps' lower quartile "
    "(0: verification.max_error alone)");
  v("hessian_loop_information", o.hessian_loop_information, nullptr,
    "loop edges' information shaped by the match's Hessian (false: diagonal sigmas)");
  v("sliding_information_kept", o.sliding_information_kept, nullptr,
    "share of a sliding loop's information kept along its open direction (0: none)");
  describe(o.candidates, v);  // flat: its keys stand here in the loop closure's object
  v("max_correction", o.max_correction, nullptr,
    "A verified loop may move the estimate by this many m ...");
  v("max_correction_per_m", o.max_correction_per_m, nullptr,
    "... plus this share of the path between the two keyframes");
  v("registration_reach", o.registration_reach, nullptr,
    "How far verification can move a place-database match, m (negative: all are verified)");
  v("widening_per_weak_step", o.widening_per_weak_step, nullptr,
    "Each weak odometry step between two keyframes widens their loop search by this factor more");
  v("max_doubt_widening", o.max_doubt_widening, nullptr,
    "... up to this many times the proximity radius and search window");
  v("search_every", o.search_every, nullptr, "Look for loops at every this-many keyframes");
  v("keyframes_between_loops", o.keyframes_between_loops, nullptr,
    "Keyframes without a search after one that added a loop");
  v("optimize_above", o.optimize_above, nullptr,
    "Optimize when a loop moves points 5 m away by more than this, m (0: every loop)");
  v("recheck_above", o.recheck_above, nullptr,
    "When an optimization moves the new keyframe by more than this (m at 5 m) ...");
  v("recheck_keyframes", o.recheck_keyframes, nullptr,
    "... this many keyframes before it look for loops again (0: never)");
  v.nested("verification", o.verification);
  v.nested("descriptor", o.descriptor);
  v.nested("graph", o.graph);
}

}  // namespace scanmatch
