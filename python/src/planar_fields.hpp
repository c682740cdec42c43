#pragma once
// The keyword options of the 2D bindings, in the visitor form of odometry/config_fields.hpp
// (which describes the 3D configuration only). Help texts are short: the header comments of
// Registration2DOptions and Mapper2DConfig say more. PathRules::shared (an enum) is not a
// keyword; its default (keep_all) applies.

#include "scanmatch/odometry/mapper2d.hpp"

namespace scanmatch {

template <typename Visitor>
void describe(PathRules& p, Visitor& v) {
  v("max_step", p.max_step, nullptr, "sparse-icp: largest normal step of the path, rows");
  v("max_run", p.max_run, nullptr, "sparse-icp keep_all: longest run of columns on one row");
}

template <typename Visitor>
void describe(Registration2DOptions& r, Visitor& v) {
  v("max_iterations", r.max_iterations, nullptr, "iteration limit");
  v("tolerance", r.tolerance, nullptr, "m and rad: stop below this step");
  v("max_correspondence_distance", r.max_correspondence_distance, nullptr,
    "m: sparse-icp's Manhattan threshold D; the baselines' rejection distance");
  v("histogram_bin", r.histogram_bin, nullptr, "sparse-icp: angle histogram bin, rad");
  v("histogram_min_segment", r.histogram_min_segment, nullptr,
    "sparse-icp: shortest histogram segment, m");
  v("histogram_max_rotation", r.histogram_max_rotation, nullptr,
    "sparse-icp: histogram rotation search window, rad");
  v("coarse_rotation", r.coarse_rotation, nullptr, "sparse-icp: angle-histogram rotation");
  v("coarse_translation", r.coarse_translation, nullptr, "sparse-icp: centroid translation");
  v("subsample_projection", r.subsample_projection, nullptr,
    "sparse-icp: project pairs onto the reference segments");
  v("sparse_step", r.sparse_step, nullptr, "sparse-icp's step: svd or point-to-line");
  v("sparse_tolerance", r.sparse_tolerance, nullptr, "sparse-icp's stop, m and rad");
  v("sparse_keep_fraction", r.sparse_keep_fraction, nullptr, "sparse-icp: fraction of pairs kept");
  v("sparse_min_pairs", r.sparse_min_pairs, nullptr,
    "sparse-icp: stop below this fraction of paired points");
  v("sparse_line_radius", r.sparse_line_radius, nullptr, "sparse-icp: line fit radius, m");
  v("pl_line_radius", r.pl_line_radius, nullptr, "pl-icp: line fit radius, m (0: Censi)");
  v("normal_angle", r.normal_angle, nullptr, "normal-icp's rejection angle, rad");
  v("keep_fraction", r.keep_fraction, nullptr, "pl-icp: fraction of pairs kept");
  v("search_window", r.search_window, nullptr, "correlative search, +- m (0: off)");
  v("search_angle", r.search_angle, nullptr, "correlative search, +- rad");
  v("search_resolution", r.search_resolution, nullptr, "correlative search grid, m");
  v.nested("path_rules", r.path_rules);
}

template <typename Visitor>
void describe(Mapper2DConfig& c, Visitor& v) {
  v("constant_velocity", c.constant_velocity, nullptr, "previous motion as the initial guess");
  v("min_range", c.min_range, nullptr, "m: nearer returns are dropped");
  v("max_correction", c.max_correction, nullptr, "m: larger corrections are failed matches");
  v("max_correction_angle", c.max_correction_angle, nullptr, "rad: likewise for rotation");
  v("keyframe_distance", c.keyframe_distance, nullptr, "m: new keyframe after this motion");
  v("keyframe_angle", c.keyframe_angle, nullptr, "rad: likewise for rotation");
  v("deskew", c.deskew, nullptr, "deskew scans with point times");
  v.nested("registration", c.registration);
}

}  // namespace scanmatch
