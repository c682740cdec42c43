#pragma once
// What a run adds to the modules' options (the exported map, loop closure on or off, map2d's
// grid and loop settings), and the whole configuration of `odometry` and `map2d` as their
// RUNDIR/config.json holds it (the protocol: config/fields.hpp).
#include "scanmatch/config/mapping2d_fields.hpp"
#include "scanmatch/config/mapping_fields.hpp"
#include "scanmatch/config/odometry_fields.hpp"
#include "scanmatch/run/map2d_run.hpp"
#include "scanmatch/run/run_config.hpp"

namespace scanmatch {

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
