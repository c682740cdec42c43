#pragma once
// The 2D mapper's and occupancy grid's options, described once (the protocol: fields.hpp).
#include "scanmatch/config/registration_fields.hpp"
#include "scanmatch/mapping2d/grid_map.hpp"
#include "scanmatch/mapping2d/mapper2d.hpp"

namespace scanmatch {

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
  v("open_step_speed_steps", c.open_step_speed_steps, nullptr,
    "steps whose median length is the prior straight on where the turning prior is "
    "contradicted (0: off)");
  v("long_search_window", c.long_search_window, nullptr,
    "m: search again over +- this where the step is weak or open (0: off)");
  v("long_search_below", c.long_search_below, nullptr,
    "share of points fitting below which the long search runs");
  v("reference_fit_below", c.reference_fit_below, nullptr,
    "share of points fitting below which a scan is not the next scan's reference (0: off)");
  v("max_unfit_references_skipped", c.max_unfit_references_skipped, nullptr,
    "scans in a row at most kept from being the reference for fitting poorly");
  v("unfit_max_correction", c.unfit_max_correction, nullptr,
    "while the motion is steady, a scan fitting below reference_fit_below is bridged by the prior "
    "when it departs more than this many m from it (0: no bound)");
  v("unfit_max_correction_angle", c.unfit_max_correction_angle, nullptr,
    "... and this many rad (0: no bound)");
  v("unfit_steady_steps", c.unfit_steady_steps, nullptr,
    "... steady: the last this-many steps each lie within those bounds of the last one");
  v("submap_scans", c.submap_scans, nullptr,
    "references the search scores against: the last and the ones before it (1: scan to scan)");
  v("submap_link_fit", c.submap_link_fit, nullptr,
    "share of points fitting below which a step lets the older references go");
  v.nested("registration", c.registration);
}

template <typename Visitor>
void describe(GridMapOptions& g, Visitor& v) {
  v("resolution", g.resolution, "--grid-resolution", "Grid cell size, m");
  v("max_cells", g.max_cells, nullptr, "most cells a grid may hold (4 bytes each)");
  v("hit_log_odds", g.hit_log_odds, nullptr, "log-odds added where a beam ends");
  v("miss_log_odds", g.miss_log_odds, nullptr, "log-odds added where a beam passes");
  v("min_log_odds", g.min_log_odds, nullptr, "lower clamp of a cell's log-odds");
  v("max_log_odds", g.max_log_odds, nullptr, "upper clamp of a cell's log-odds");
  v("occupied_threshold", g.occupied_threshold, nullptr, "probability of an occupied cell");
  v("free_threshold", g.free_threshold, nullptr, "probability of a free cell");
}

}  // namespace scanmatch
