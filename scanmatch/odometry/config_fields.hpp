#pragma once
// The one description of the configuration: every field's JSON key, its command-line flag (if it
// has one) and its help text. config_io.cpp reads and writes JSON from it; the CLI adds its
// options from it, and a --config file is overridden by exactly the flags given on the command
// line. A new option is one line here.
//
// A visitor provides
//   template <class T> void operator()(const char* key, T& field, const char* flag,
//                                      const char* help);   // flag nullptr: JSON only
//   template <class S> void nested(const char* key, S& options);  // a nested object
// and describe(options, visitor) calls it for every field. Enumerations are named (enum_name,
// enum_from_name); angles are radians in JSON and Python (the CLI may offer degrees). A bool
// field whose flag starts with "--no-" is switched off by it (`--no-fine`: fine_stage = false);
// any other bool flag switches its field on.

#include "scanmatch/core/error.hpp"
#include "scanmatch/odometry/config_io.hpp"
#include "scanmatch/odometry/odometry.hpp"
#include "scanmatch/odometry/run2d.hpp"

namespace scanmatch {

inline const char* enum_name(KernelType type) {
  return kernel_name(type);
}
inline void enum_from_name(const std::string& name, KernelType& type) {
  type = parse_kernel(name);
}
inline const char* enum_name(PathRules::Shared shared) {
  return to_string(shared);
}
inline void enum_from_name(const std::string& name, PathRules::Shared& shared) {
  shared = parse_shared_rows(name);
}
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
void describe(SolverOptions& s, Visitor& v) {
  v("max_iterations", s.max_iterations, "--max-iterations",
    "Iteration limit of each registration (the method's solver)");
  v("rotation_tolerance", s.rotation_tolerance, nullptr, "rad: converged below this update");
  v("translation_tolerance", s.translation_tolerance, nullptr, "m: converged below this update");
  v("relative_cost_tolerance", s.relative_cost_tolerance, nullptr,
    "converged when the cost changes relatively less than this");
  v("levenberg_marquardt", s.levenberg_marquardt, "--lm",
    "Levenberg-Marquardt instead of Gauss-Newton");
  v("initial_lambda", s.initial_lambda, nullptr, "initial LM damping");
  v("kernel", s.kernel.type, "--kernel",
    "Robust kernel: none, huber, cauchy, tukey, geman-mcclure");
  v("kernel_scale", s.kernel.scale, "--kernel-scale", "Robust kernel scale, m");
}

template <typename Visitor>
void describe(LoamFeatureOptions& l, Visitor& v) {
  v("neighbours", l.neighbours, nullptr, "points on each side on the same ring");
  v("segments", l.segments, nullptr, "equal segments per ring");
  v("edges_per_segment", l.edges_per_segment, nullptr, "edge points per segment");
  v("planes_per_segment", l.planes_per_segment, nullptr, "planar points per segment");
  v("edge_threshold", l.edge_threshold, nullptr, "curvature above this can be an edge");
  v("plane_threshold", l.plane_threshold, nullptr, "curvature below this can be planar");
  v("occlusion_ratio", l.occlusion_ratio, nullptr, "relative range jump of an occlusion");
  v("rings", l.rings, nullptr, "ring count for clouds without a ring field");
}

template <typename Visitor>
void describe(RegistrationOptions& r, Visitor& v) {
  v("max_correspondence_distance", r.max_correspondence_distance, "--max-distance",
    "Correspondence distance of the point-based methods, m");
  v("normal_neighbours", r.normal_neighbours, nullptr, "k for normals (point-to-plane)");
  v("covariance_neighbours", r.covariance_neighbours, nullptr, "k for covariances (gicp, vgicp)");
  v("gicp_epsilon", r.gicp_epsilon, nullptr, "smallest normalised eigenvalue of GICP covariances");
  v("voxel_resolution", r.voxel_resolution, "--voxel-resolution",
    "Gaussian voxel grid of the ndt, vgicp and ctf-fine methods, m");
  v("voxel_neighbours", r.voxel_neighbours, "--voxel-neighbours",
    "Voxels per point of ndt, vgicp, ctf-fine: 1, 7 or 27 (0: the method's default)");
  v("ndt_outlier_ratio", r.ndt_outlier_ratio, nullptr, "NDT's outlier probability");
  v("ctf_epsilon", r.ctf_epsilon, nullptr, "CTF-ICP's normalised smallest eigenvalue");
  v.nested("solver", r.solver);
  v.nested("loam", r.loam);
}

template <typename Visitor>
void describe(OdometryConfig& c, Visitor& v) {
  v("method", c.method, "--method", "ctf-icp or a registration method, frame to frame");
  v("voxel_size", c.voxel_size, "--voxel", "Downsampling voxel of every frame, m (0: none)");
  v("min_range", c.min_range, "--min-range", "Nearer points are dropped, m");
  v("max_range", c.max_range, "--max-range", "Farther points are dropped, m");
  v("ndt_resolution", c.ndt_resolution, "--ndt-resolution",
    "ctf-icp: the coarse stage's NDT grid of the previous frame, m");
  v("ndt_neighbours", c.ndt_neighbours, nullptr, "ctf-icp coarse: voxels per point");
  v("coarse_voxel_size", c.coarse_voxel_size, nullptr, "ctf-icp: downsampling of the NDT source");
  v("coarse_max_iterations", c.coarse_max_iterations, "--coarse-max-iterations",
    "ctf-icp: the coarse NDT stage's iteration limit");
  v("coarse_tolerance", c.coarse_tolerance, nullptr,
    "ctf-icp: the coarse stage's update tolerance");
  v("map_voxel_size", c.map_voxel_size, "--map-voxel",
    "ctf-icp: the global Gaussian map's voxel, m");
  v("merge_threshold", c.merge_threshold, "--merge-threshold",
    "ctf-icp: new points a map voxel collects before it is merged");
  v("map_radius", c.map_radius, "--map-radius",
    "ctf-icp: map voxels farther than this are dropped, m");
  v("map_voxel_min_points", c.map_voxel_min_points, nullptr, "points a map voxel needs to be used");
  v("map_voxel_max_points", c.map_voxel_max_points, nullptr, "points after which a voxel freezes");
  v("fine_max_iterations", c.fine_max_iterations, "--fine-max-iterations",
    "ctf-icp: the fine stage's Gauss-Newton steps");
  v("fine_tolerance", c.fine_tolerance, nullptr, "ctf-icp: the fine stage's update tolerance");
  v("fine_max_flatness", c.fine_max_flatness, nullptr, "ctf-icp: flattest map voxels used");
  v("fine_kernel_distance", c.fine_kernel_distance, nullptr, "ctf-icp: Cauchy kernel distance, m");
  v("degeneracy_guard_ratio", c.degeneracy_guard_ratio, "--degeneracy-guard-ratio",
    "ctf-icp: no fine-stage update along directions below this scaled eigenvalue ratio (0: off)");
  v("degeneracy_guard_frames", c.degeneracy_guard_frames, "--degeneracy-guard-frames",
    "ctf-icp: over this many first frames the guard uses degeneracy_ratio");
  v("degeneracy_ratio", c.degeneracy_ratio, "--degeneracy-ratio",
    "ctf-icp: scaled eigenvalue ratio below which a direction is reported degenerate (0: never)");
  v("fine_stage", c.fine_stage, "--no-fine", "Ablation: ctf-icp's coarse NDT stage only");
  v("map_update", c.map_update, "--no-map-update",
    "Ablation: ctf-icp's fine stage against the previous frame, no global map");
  v("constant_velocity", c.constant_velocity, nullptr, "constant-velocity motion prior");
  v("deskew", c.deskew, "--no-deskew", "Do not correct motion distortion");
  v("deskew_min_translation", c.deskew_min_translation, nullptr, "deskew dead band, m per frame");
  v("deskew_min_rotation", c.deskew_min_rotation, nullptr, "deskew dead band, rad per frame");
  v("redeskew_translation", c.redeskew_translation, nullptr,
    "deskew again by the registered motion where it misses the prior by this, m per frame");
  v("redeskew_rotation", c.redeskew_rotation, nullptr,
    "likewise for rotation, rad per frame (both 0: never)");
  v("spin_times", c.spin_times, "--spin-times",
    "Frames without point times (a spinning LiDAR's raw sweeps, e.g. KITTI raw .bin): derive each "
    "point's time from its azimuth, so they are deskewed");
  v("spin_period", c.spin_period, nullptr, "spin_times: s per turn of the sensor");
  v("spin_start_azimuth", c.spin_start_azimuth, nullptr,
    "spin_times: azimuth where each sweep starts, rad (atan2(y, x); 0: along +x)");
  v("spin_clockwise", c.spin_clockwise, nullptr,
    "spin_times: the sensor turns clockwise seen from above (azimuth decreasing with time)");
  v("anchor_min_translation", c.anchor_min_translation, nullptr,
    "the first motion's translation anchors the world (frame 0's start) above this, m per frame");
  v("anchor_min_rotation", c.anchor_min_rotation, nullptr,
    "likewise for its rotation, rad per frame");
  v("max_jump", c.max_jump, nullptr, "results farther from the prior are rejected, m");
  v("max_jump_angle", c.max_jump_angle, nullptr, "likewise for rotation, rad");
  v("time_scaled_prior", c.time_scaled_prior, nullptr,
    "scale the constant-velocity prior by the ratio of the frame time steps");
  v("max_step_ratio", c.max_step_ratio, nullptr,
    "time-step ratios beyond this (or its inverse) make the prior uncertain");
  v("prior_miss_distance", c.prior_miss_distance, nullptr,
    "an estimate this far from its prior makes the next prior uncertain, m");
  v("prior_miss_angle", c.prior_miss_angle, nullptr, "likewise for rotation, rad");
  v("uncertain_rotation", c.uncertain_rotation, nullptr,
    "a prior that turns more than this in one step is uncertain, rad");
  v("uncertain_starts", c.uncertain_starts, nullptr,
    "ctf-icp, uncertain prior: also try the identity, half and twice the prior motion and the "
    "prior turned about the sensor's z axis");
  v("rotation_starts", c.rotation_starts, nullptr,
    "ctf-icp, uncertain prior: turned starts per side, +-k * rotation_start_step (0: none)");
  v("rotation_start_step", c.rotation_start_step, nullptr,
    "ctf-icp: angle between turned starts, rad");
  v("uncertain_ndt_scale", c.uncertain_ndt_scale, nullptr,
    "ctf-icp: those starts run first on an NDT grid this many times ndt_resolution");
  v("wide_start_iterations", c.wide_start_iterations, nullptr,
    "ctf-icp: a certain prior whose NDT solve took this many iterations also starts on the wider "
    "grid (uncertain_ndt_scale), kept when it scores better (0: never)");
  v("start_screen_points", c.start_screen_points, nullptr,
    "ctf-icp, uncertain prior: the other starts are first solved and ranked on about this many "
    "coarse points (0: every start solved on every point; 150 is 2-5x cheaper on recorded "
    "keyframes, see docs/benchmarks.md)");
  v("start_full_solves", c.start_full_solves, nullptr,
    "ctf-icp: only this many best-ranked starts that beat the prior's result on that subset are "
    "then solved on every point");
  v("uncertain_jump_scale", c.uncertain_jump_scale, nullptr,
    "max_jump and max_jump_angle widen by this factor under an uncertain prior");
  v("min_downsampled_points", c.min_downsampled_points, nullptr,
    "sparse frames (below 10x this) keeping fewer points get smaller voxels, to voxel_size / 4 "
    "(0: off)");
  v("dense_sparse_map", c.dense_sparse_map, nullptr,
    "ctf-icp, sparse frames: the map gets the frame at voxel_size / 4, so one keyframe makes "
    "usable map voxels");
  v("threads", c.threads, "--threads", "Threads (1 for fair comparisons)");
  v.nested("registration", c.registration);
}

// RunOptions' fields that make up a run's result (the exported map); the others belong to one
// invocation (folder, frame limit, quiet, stop) and are not configuration.
template <typename Visitor>
void describe(RunOptions& r, Visitor& v) {
  v("save", r.write_map, "--save-map", "Write RUNDIR/map.pcd (or .ply)");
  v("format", r.map_format, "--map-format", "Exported map format: pcd or ply");
  v("voxel_size", r.map_voxel_size, "--map-export-voxel", "Exported map voxel, m");
  v("radius", r.map_export_radius, "--map-export-radius",
    "Export only points within this radius of the last pose, m (0: all)");
}

// RUNDIR/config.json: the OdometryConfig's keys at the top level, as before "map_export" existed.
template <typename Visitor>
void describe(OdometryRunConfig& c, Visitor& v) {
  describe(c.odometry, v);
  v("loop_closure", c.output.loop_closure, "--loop-closure",
    "3D loop closure: a pose graph over keyframes, verified loops, poses_optimized*.txt, "
    "loops.json, map.* from the optimized poses");
  v("loop_closure_thread", c.output.loop_closure_thread, "--no-loop-closure-thread",
    "Run loop closure inline, not on its own thread (same results)");
  v.nested("map_export", c.output);
  v.nested("loop", c.output.loop);
}

// `register`: the registration's own keys, and the downsampling of both clouds.
template <typename Visitor>
void describe(PairRegistrationOptions& p, Visitor& v) {
  v("voxel_size", p.voxel_size, "--voxel", "Voxel downsampling of both clouds, m (0: none)");
  describe(p.registration, v);
}

// 2D: map2d's run (Map2DRunOptions) and what it nests.

template <typename Visitor>
void describe(PathRules& p, Visitor& v) {
  v("max_step", p.max_step, "--path-max-step",
    "sparse-icp: reference rows a kept pair may skip (1: the paper)");
  v("shared", p.shared, "--shared-rows",
    "sparse-icp: points sharing a reference point: drop (the paper), keep-nearest or keep-all");
  v("max_run", p.max_run, nullptr, "sparse-icp keep-all: longest run of points on one row");
}

template <typename Visitor>
void describe(Registration2DOptions& r, Visitor& v) {
  v("method", r.method, "--method", "A 2D registration method");
  v("max_iterations", r.max_iterations, "--max-iterations", "Iteration limit of each registration");
  v("tolerance", r.tolerance, nullptr, "m and rad: stop below this step");
  v("max_correspondence_distance", r.max_correspondence_distance, "--max-distance",
    "Correspondence distance: sparse-icp's Manhattan threshold D, the baselines' rejection, m");
  v("histogram_bin", r.histogram_bin, nullptr, "sparse-icp: angle histogram bin, rad");
  v("histogram_min_segment", r.histogram_min_segment, nullptr,
    "sparse-icp: shortest histogram segment, m");
  v("histogram_max_rotation", r.histogram_max_rotation, nullptr,
    "sparse-icp: histogram rotation search window, rad");
  v("coarse_rotation", r.coarse_rotation, nullptr, "sparse-icp: angle-histogram rotation");
  v("coarse_translation", r.coarse_translation, "--centroid-translation",
    "sparse-icp: the paper's centroid translation in the coarse stage");
  v("subsample_projection", r.subsample_projection, nullptr,
    "sparse-icp: project pairs onto the reference segments");
  v("sparse_step", r.sparse_step, "--sparse-step",
    "sparse-icp's step on the kept pairs: svd (the paper) or point-to-line");
  v("sparse_tolerance", r.sparse_tolerance, nullptr, "sparse-icp's stop, m and rad");
  v("sparse_keep_fraction", r.sparse_keep_fraction, nullptr, "sparse-icp: fraction of pairs kept");
  v("sparse_min_pairs", r.sparse_min_pairs, nullptr,
    "sparse-icp: stop below this fraction of paired points");
  v("sparse_line_radius", r.sparse_line_radius, "--line-radius",
    "sparse-icp: lines are fitted to the reference within this radius, m (0: the segment to the "
    "next beam)");
  v("pl_line_radius", r.pl_line_radius, nullptr, "pl-icp: line fit radius, m (0: Censi)");
  v("normal_angle", r.normal_angle, nullptr, "normal-icp's rejection angle, rad");
  v("keep_fraction", r.keep_fraction, nullptr, "pl-icp: fraction of pairs kept");
  v("search_window", r.search_window, "--search-window",
    "Correlative coarse search over +- this many m before matching (0: off)");
  v("search_angle", r.search_angle, nullptr, "correlative search, +- rad");
  v("search_resolution", r.search_resolution, nullptr, "correlative search grid, m");
  v("search_fill_gap", r.search_fill_gap, "--search-fill-gap",
    "Correlative search: fill straight surfaces between returns up to this many m apart (0: off)");
  v("fine_fit_margin", r.fine_fit_margin, nullptr,
    "m: after the search, the method's pose must fit within this of the search's (<0: off)");
  v.nested("path_rules", r.path_rules);
}

template <typename Visitor>
void describe(Mapper2DConfig& c, Visitor& v) {
  v("constant_velocity", c.constant_velocity, nullptr, "previous motion as the initial guess");
  v("min_range", c.min_range, nullptr, "m: nearer returns are dropped");
  v("max_correction", c.max_correction, nullptr, "m: larger corrections are failed matches");
  v("max_correction_angle", c.max_correction_angle, nullptr, "rad: likewise for rotation");
  v("keyframe_distance", c.keyframe_distance, "--keyframe-distance",
    "Match against the last keyframe, replaced after this many m (0: scan to scan)");
  v("keyframe_angle", c.keyframe_angle, nullptr, "rad: likewise for rotation");
  v("deskew", c.deskew, "--deskew",
    "Deskew scans by the last step's motion (experimental: see docs/planar.md)");
  v("wide_search_angle", c.wide_search_angle, nullptr,
    "rad: search again over +- this where few points fit (0: off)");
  v("wide_search_below", c.wide_search_below, nullptr,
    "share of points within 15 cm of the reference below which the wide search runs");
  v("full_turn_search_below", c.full_turn_search_below, nullptr,
    "share of points fitting after the wide search below which it runs over +- 180 deg (0: off)");
  v("open_step_window", c.open_step_window, nullptr,
    "m: where the scans leave a step open within this, the motion prior chooses (0: off)");
  v("open_step_margin", c.open_step_margin, nullptr,
    "share of the points: translations fitting within it of the best leave the step open");
  v("open_step_spread", c.open_step_spread, nullptr,
    "m: RMS spread of those translations from which the step counts as open");
  v("open_step_prior_distance", c.open_step_prior_distance, nullptr,
    "m: the prior chooses only when a fitting translation lies this near it");
  v("long_search_window", c.long_search_window, nullptr,
    "m: search again over +- this where the step is weak or open (0: off)");
  v("long_search_below", c.long_search_below, nullptr,
    "share of points fitting below which the long search runs");
  v.nested("registration", c.registration);
}

template <typename Visitor>
void describe(GridMapOptions& g, Visitor& v) {
  v("resolution", g.resolution, "--grid-resolution", "Grid cell size, m");
  v("hit_log_odds", g.hit_log_odds, nullptr, "log-odds added where a beam ends");
  v("miss_log_odds", g.miss_log_odds, nullptr, "log-odds added where a beam passes");
  v("min_log_odds", g.min_log_odds, nullptr, "lower clamp of a cell's log-odds");
  v("max_log_odds", g.max_log_odds, nullptr, "upper clamp of a cell's log-odds");
  v("occupied_threshold", g.occupied_threshold, nullptr, "probability of an occupied cell");
  v("free_threshold", g.free_threshold, nullptr, "probability of a free cell");
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
  v("proximity_radius", o.proximity_radius, nullptr,
    "Candidates within this distance in the current estimate, m");
  v("max_proximity_candidates", o.max_proximity_candidates, nullptr,
    "Pose-proximity candidates per keyframe, at most");
  v("max_descriptor_distance", o.max_descriptor_distance, nullptr,
    "Place-database candidates below this descriptor distance");
  v("max_descriptor_candidates", o.max_descriptor_candidates, nullptr,
    "Place-database candidates per keyframe, at most");
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
  v("loop_sigma_xy", o.loop_sigma_xy, nullptr, "Loop edge standard deviation, m");
  v("loop_sigma_theta", o.loop_sigma_theta, nullptr, "Loop edge standard deviation, rad");
  v("skip_recent", o.skip_recent, nullptr, "Newest keyframes that are never candidates");
  v("submap_keyframes", o.submap_keyframes, nullptr,
    "the candidate's neighbours within this many keyframes join it for verification");
  v("hessian_loop_information", o.hessian_loop_information, nullptr,
    "loop edges' information shaped by the match's Hessian (false: diagonal sigmas)");
  v("sliding_information_kept", o.sliding_information_kept, nullptr,
    "share of a sliding loop's information kept along its open direction (0: none)");
  v("proximity_radius", o.proximity_radius, nullptr,
    "Candidates within this distance in the current estimate, m");
  v("max_proximity_candidates", o.max_proximity_candidates, nullptr,
    "Pose-proximity candidates per keyframe, at most");
  v("max_descriptor_distance", o.max_descriptor_distance, nullptr,
    "Place-database candidates below this descriptor distance");
  v("max_descriptor_candidates", o.max_descriptor_candidates, nullptr,
    "Place-database candidates per keyframe, at most");
  v("max_correction", o.max_correction, nullptr,
    "A verified loop may move the estimate by this many m ...");
  v("max_correction_per_m", o.max_correction_per_m, nullptr,
    "... plus this share of the path between the two keyframes");
  v("search_every", o.search_every, nullptr, "Look for loops at every this-many keyframes");
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

template <typename Visitor>
void describe(Map2DRunOptions& o, Visitor& v) {
  v("miss_range", o.miss_range, "--miss-range",
    "No-return beams free the grid out to this range, m (0: not at all)");
  v("reference_map", o.reference_map, "--reference-map",
    "Also build map_reference.* from the input's reference poses");
  v("loop_closure", o.loop_closure, "--loop-closure",
    "2D loop closure: a pose graph over keyframes, verified loops, map.* from optimized poses");
  v("loop_closure_thread", o.loop_closure_thread, "--no-loop-closure-thread",
    "Run loop closure inline, not on its own thread (same results)");
  v.nested("loop", o.loop);
  v.nested("mapper", o.mapper);
  v.nested("grid", o.grid);
}

}  // namespace scanmatch
