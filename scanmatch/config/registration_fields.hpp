#pragma once
// The registration methods' options (3D and 2D), described once (the protocol: fields.hpp).
#include "scanmatch/config/fields.hpp"
#include "scanmatch/features/loam_features.hpp"
#include "scanmatch/registration/options.hpp"
#include "scanmatch/registration/planar/correspondence_path.hpp"
#include "scanmatch/registration/planar/registration2d.hpp"
#include "scanmatch/registration/solver.hpp"

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

// `register`: the registration's own keys, and the downsampling of both clouds.
template <typename Visitor>
void describe(PairRegistrationOptions& p, Visitor& v) {
  v("voxel_size", p.voxel_size, "--voxel", "Voxel downsampling of both clouds, m (0: none)");
  describe(p.registration, v);
}

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

}  // namespace scanmatch
