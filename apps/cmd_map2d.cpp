// `scanmatch map2d SEQUENCE --method NAME --out RUNDIR`: 2D scan-to-scan mapping with an occupancy
// grid, evaluated against the reference poses when the input has them.

#include <fmt/format.h>

#include "apps/commands.hpp"
#include "apps/interrupt.hpp"
#include "scanmatch/core/error.hpp"
#include "scanmatch/odometry/run2d.hpp"

namespace scanmatch::cli {
namespace {

struct Map2DCommand {
  std::string sequence, out, initial = "identity";
  std::size_t scans = 0;
  std::uint64_t seed = 1;
  bool no_motion_distortion = false;
  std::string shared_rows = to_string(Registration2DOptions{}.path_rules.shared);
  double rotation_period = -1.0;  ///< s; negative: the input's own
  double search_angle_deg = 45.0, keyframe_angle_deg = 0.0;
  Map2DRunOptions run;
};

}  // namespace

void add_map2d_command(CLI::App& app) {
  auto c = std::make_shared<Map2DCommand>();
  Registration2DOptions& r = c->run.mapper.registration;
  // Scans of the classic logs are up to 1.5 m and 78 deg apart: the search is on by default.
  r.search_window = 1.3;
  auto* cmd =
      app.add_subcommand("map2d", "2D laser scan-to-scan mapping: poses and an occupancy grid");
  cmd->add_option("SEQUENCE", c->sequence,
                  "A CARMEN log (.log, .log.gz), a simulated 2D data set folder or sim:room-2d")
      ->required();
  cmd->add_option("--out", c->out, "Run folder (created)")->required();
  cmd->add_option("--method", r.method, "sparse-icp, icp, icp-kdtree, pl-icp or normal-icp")
      ->capture_default_str();
  cmd->add_option("--initial", c->initial, "Initial guess: constant-velocity or identity")
      ->capture_default_str();
  cmd->add_option("--scans", c->scans, "Process at most this many scans (0: all)");
  cmd->add_option("--seed", c->seed, "Seed of sim: sequences")->capture_default_str();
  cmd->add_flag("--no-motion-distortion", c->no_motion_distortion,
                "sim: sequences: measure each scan from its start pose");
  cmd->add_option("--rotation-period", c->rotation_period,
                  "s per turn of the laser, for deskewing (default: the simulated sensor's; "
                  "unknown for logs, so they are not deskewed)");
  cmd->add_flag("--deskew", c->run.mapper.deskew,
                "Deskew scans by the last step's motion (experimental: see docs/planar.md)");
  cmd->add_option("--max-distance", r.max_correspondence_distance,
                  "Correspondence distance threshold D, m")
      ->capture_default_str();
  cmd->add_option("--max-iterations", r.max_iterations)->capture_default_str();
  cmd->add_option("--search-window", r.search_window,
                  "Correlative coarse search over +- this many m before matching (0: off)")
      ->capture_default_str();
  cmd->add_option("--search-angle", c->search_angle_deg, "Correlative search, +- deg")
      ->capture_default_str();
  cmd->add_option("--keyframe-distance", c->run.mapper.keyframe_distance,
                  "Match against the last keyframe, replaced after this many m (0: scan to scan)")
      ->capture_default_str();
  cmd->add_option("--keyframe-angle", c->keyframe_angle_deg,
                  "... or after this many deg of turn (0: not by angle)")
      ->capture_default_str();
  cmd->add_option("--sparse-step", r.sparse_step,
                  "sparse-icp's step on the kept pairs: svd (the paper) or point-to-line")
      ->capture_default_str();
  cmd->add_option("--path-max-step", r.path_rules.max_step,
                  "sparse-icp: reference rows a kept pair may skip (1: the paper)")
      ->capture_default_str();
  cmd->add_option("--shared-rows", c->shared_rows,
                  "sparse-icp: points sharing a reference point: drop (the paper), keep-nearest "
                  "or keep-all")
      ->capture_default_str();
  cmd->add_option("--line-radius", r.sparse_line_radius,
                  "sparse-icp: lines are fitted to the reference within this radius, m (0: the "
                  "segment to the next beam)")
      ->capture_default_str();
  cmd->add_flag("--centroid-translation", r.coarse_translation,
                "sparse-icp: the paper's centroid translation in the coarse stage");
  cmd->add_option("--resolution", c->run.grid.resolution, "Grid cell size, m")
      ->capture_default_str();
  cmd->add_option("--miss-range", c->run.miss_range,
                  "No-return beams free the grid out to this range, m (0: not at all)")
      ->capture_default_str();
  cmd->add_flag("--reference-map", c->run.reference_map,
                "Also build map_reference.* from the input's reference poses");
  cmd->add_flag("--quiet", c->run.quiet, "No progress and no summary lines");
  cmd->callback([c] {
    if (c->initial != "constant-velocity" && c->initial != "identity")
      throw Error("map2d: --initial must be constant-velocity or identity");
    c->run.mapper.constant_velocity = c->initial == "constant-velocity";
    c->run.mapper.registration.search_angle = c->search_angle_deg * M_PI / 180;
    c->run.mapper.keyframe_angle = c->keyframe_angle_deg * M_PI / 180;
    c->run.mapper.registration.path_rules.shared = parse_shared_rows(c->shared_rows);
    Scans2D input = load_scans_2d(c->sequence, c->scans, c->seed, !c->no_motion_distortion);
    if (c->rotation_period >= 0.0) input.rotation_period = c->rotation_period;
    Map2DSummary s;
    {
      const InterruptFlag interrupt;
      c->run.stop = interrupt.flag();
      s = run_map2d(input, c->out, c->run);
    }
    if (!c->run.quiet) {
      fmt::print("map2d {}: {} scans, {} bridged, {:.2f} ms per scan ({:.0f} scans/s){}\n",
                 c->run.mapper.registration.method, s.scans, s.bridged, s.mean_ms,
                 s.scans_per_second, s.interrupted ? ", interrupted" : "");
      for (const RelativeError2D* e : {&s.one_step, &s.ten_steps})
        if (e->pairs > 0)
          fmt::print(
              "relative error over {:>2} scans: mean {:.0f} mm / {:.2f} deg, median {:.0f} mm / "
              "{:.2f} deg, failures {:.1f} %\n",
              e->step, 1000 * e->mean_translation, e->mean_rotation * 180 / M_PI,
              1000 * e->median_translation, e->median_rotation * 180 / M_PI, 100 * e->failure_rate);
      if (!s.map_error.empty()) fmt::print("no map written: {}\n", s.map_error);
      fmt::print("run folder: {}\n", c->out);
    }
    if (s.interrupted) throw CLI::RuntimeError(130);
  });
}

}  // namespace scanmatch::cli
