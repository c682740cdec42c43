#pragma once
// The report's interactive 3D view: the map as points (coloured by height or intensity), every
// run's odometry and loop-closed trajectories, the reference, the loop edges and the frames the
// health record flagged (hover or click a frame: its index, step error and flags), with orbit,
// pan, zoom and top, side and follow views. map2d runs show their occupancy grid as a textured
// plane under the trajectories. three.js (Debian's libjs-three) is inlined when the page is made,
// so the page still needs nothing at view time; without it the section is a note and the page
// keeps its 2D views. The page reports what it drew in #view3d-status (JSON: points, trajectory
// vertices, loop edges, flagged frames, script errors) for tests to read.

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/run/run_folder.hpp"
#include "scanmatch/sim/open_sequence.hpp"

namespace scanmatch {

/// Where Debian's libjs-three puts three.min.js (and examples/js/controls/OrbitControls.js).
inline constexpr const char* kDefaultThreeJsDir = "/usr/share/javascript/three";

struct View3DOptions {
  bool enabled = true;
  /// Folder of three.min.js; empty: $SCANMATCH_THREE_JS_DIR when set, else kDefaultThreeJsDir.
  std::string three_js_dir;
  /// Map points in the page at most (6 bytes each before base64, 8 after).
  std::size_t max_points = 1'000'000;
  /// The sequence the first run read (a spec as `odometry` takes): the map is rebuilt from its
  /// frames and that run's poses (in place of a saved map, which has no intensities). `sequence`
  /// as the run opened it.
  std::string frames;
  SequenceOptions sequence;
};

/// At most `max_points` of `cloud`, spread evenly over it: a voxel grid at the smallest edge
/// (from 2 cm, to within a factor 1.19) that leaves at most 1.3 x max_points voxels, then every
/// n-th of those. Intensities (when present) follow their points; non-finite points are dropped.
/// A cloud within the budget is returned as is otherwise.
PointCloud downsample_to_budget(const PointCloud& cloud, std::size_t max_points);

/// A map rebuilt from frames: every frame's points placed by its pose (the run's loop-closed
/// poses when it has them, else its odometry; no deskewing), voxel-downsampled as they come so
/// that memory stays near a few times the budget, then downsample_to_budget. Throws Error when
/// the sequence has fewer frames than the run has poses or its frame times differ from the
/// poses' (not the sequence this run read).
PointCloud rebuild_map_from_frames(const RunFolder& run, const std::string& spec,
                                   const SequenceOptions& sequence, std::size_t max_points);

/// The section (heading, view, note, scripts) for render_report. Rebuilds the map from
/// options.frames when given, else reads map.pcd/map.ply of the first run that has one; shows
/// map.pgm/map.yaml of a map2d run. Throws Error naming the file for an unreadable map or grid.
std::string render_view3d(const std::vector<RunFolder>& runs,
                          const std::optional<Trajectory>& ground_truth,
                          const View3DOptions& options);

/// RFC 4648 base64 of `bytes` (with padding).
std::string base64_encode(const std::string& bytes);

/// The view's script (three.js not included), defined in report_view3d_js.cpp.
extern const char* const kView3DScript;

}  // namespace scanmatch
