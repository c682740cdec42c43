#pragma once
// The HTML report: one self-contained file (inline SVG plots made by svg_plot.hpp, the 3D view of
// report_view3d.hpp with three.js inlined, no network) comparing run folders of `scanmatch
// odometry` against a ground truth: a table of accuracy and speed, the 3D view, a top view of
// every trajectory, position error over distance; per run, the error of each step against the
// reference and the health record over frames (fine paired fraction, uncertain priors,
// coarse/fine disagreement, with the thresholds of summary.json's `health`) and the worst steps
// with what the record said there; per-stage time per frame, and a side view of the map when a
// run saved one.

#include <optional>
#include <string>
#include <vector>

#include "scanmatch/run/report_view3d.hpp"
#include "scanmatch/run/run_folder.hpp"

namespace scanmatch {

struct ReportOptions {
  std::string title = "scanmatch odometry report";
  /// Extra HTML (already escaped) inserted after the title, e.g. the benchmark's tables.
  std::string preamble_html;
  std::size_t max_map_points = 8000;  ///< side view of the map, decimated
  /// The interactive 3D view (report_view3d.hpp), after the table of runs.
  View3DOptions view3d;
};

/// What the health record says about one frame, in words ("" for a healthy one).
std::string frame_health_flags(const FrameStats& frame);

/// Renders the runs. `ground_truth` overrides the runs' own poses_gt.txt; runs without either are
/// shown without errors. Throws Error for mismatched trajectory lengths.
std::string render_report(const std::vector<RunFolder>& runs,
                          const std::optional<Trajectory>& ground_truth,
                          const ReportOptions& options = {});

}  // namespace scanmatch
