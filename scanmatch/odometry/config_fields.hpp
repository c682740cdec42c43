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
// and describe(options, visitor) calls it for every field.

#include "scanmatch/odometry/odometry.hpp"

namespace scanmatch {

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
  v("degeneracy_ratio", c.degeneracy_ratio, "--degeneracy-ratio",
    "ctf-icp: eigenvalue ratio below which a direction keeps the prior (0: off)");
  v("fine_stage", c.fine_stage, nullptr, "ctf-icp: run the fine stage (--no-fine: ablation)");
  v("map_update", c.map_update, nullptr, "ctf-icp: update the global map (--no-map-update)");
  v("constant_velocity", c.constant_velocity, nullptr, "constant-velocity motion prior");
  v("deskew", c.deskew, nullptr, "correct motion distortion (--no-deskew)");
  v("deskew_min_translation", c.deskew_min_translation, nullptr, "deskew dead band, m per frame");
  v("deskew_min_rotation", c.deskew_min_rotation, nullptr, "deskew dead band, rad per frame");
  v("max_jump", c.max_jump, nullptr, "results farther from the prior are rejected, m");
  v("max_jump_angle", c.max_jump_angle, nullptr, "likewise for rotation, rad");
  v("threads", c.threads, "--threads", "Threads (1 for fair comparisons)");
  v.nested("registration", c.registration);
}

}  // namespace scanmatch
