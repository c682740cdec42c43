// `scanmatch map2d SEQUENCE --method NAME --out RUNDIR`: 2D scan-to-scan mapping with an occupancy
// grid, evaluated against the reference poses when the input has them.

#include <fmt/format.h>

#include "apps/commands.hpp"
#include "apps/config_options.hpp"
#include "apps/interrupt.hpp"
#include "scanmatch/core/error.hpp"
#include "scanmatch/registration/planar/registration2d.hpp"
#include "scanmatch/run/map2d_run.hpp"
#include "scanmatch/run/run_config.hpp"

namespace scanmatch::cli {
namespace {

struct Map2DCommand {
  std::string sequence, out, initial = "constant-velocity", topic, config_file;
  std::size_t scans = 0, first_scan = 0;
  std::uint64_t seed = 1;
  bool no_motion_distortion = false, infer_no_return = true;
  double rotation_period = -1.0;  ///< s; negative: the input's own
  double search_angle_deg = 45.0, wide_search_angle_deg = 90.0, keyframe_angle_deg = 0.0;
  Map2DRunOptions run, defaults;
};

// The configuration: a --config file (on top of the command's defaults) overridden by the options
// given, or the options alone. --initial and the degree options are the command line's own forms
// of described fields.
Map2DRunOptions configuration(const Map2DCommand& c, const CLI::App& cmd) {
  const auto given = [&](const std::string& flag) { return cmd.count(flag) > 0; };
  const bool from_file = !c.config_file.empty();
  Map2DRunOptions run =
      from_file ? override_given_flags(read_map2d_config(c.config_file, c.defaults), c.run, given)
                : c.run;
  if (c.initial != "constant-velocity" && c.initial != "identity")
    throw Error("map2d: --initial must be constant-velocity or identity");
  if (!from_file || given("--initial"))
    run.mapper.constant_velocity = c.initial == "constant-velocity";
  if (!from_file || given("--search-angle"))
    run.mapper.registration.search_angle = c.search_angle_deg * M_PI / 180;
  if (!from_file || given("--wide-search-angle"))
    run.mapper.wide_search_angle = c.wide_search_angle_deg * M_PI / 180;
  if (!from_file || given("--keyframe-angle"))
    run.mapper.keyframe_angle = c.keyframe_angle_deg * M_PI / 180;
  run.quiet = c.run.quiet;
  return run;
}

}  // namespace

void add_map2d_command(CLI::App& app) {
  auto c = std::make_shared<Map2DCommand>();
  // From the previous step's motion: with the filled search the identity gained nothing on these
  // stop-and-go logs and lost intel's loop-closed ATE (0.34 against 0.27 m, docs/planar.md).
  c->run.mapper.constant_velocity = true;
  c->defaults = c->run;
  auto* cmd =
      app.add_subcommand("map2d", "2D laser scan-to-scan mapping: poses and an occupancy grid");
  cmd->add_option("SEQUENCE", c->sequence,
                  "A CARMEN log (.log, .log.gz), a simulated 2D data set folder, sim:room-2d, "
                  "sim:corridor-2d or a ROS bag (.bag, .db3, .mcap) with LaserScan messages")
      ->required();
  cmd->add_option("--out", c->out, "Run folder (created)")->required();
  cmd->add_option("--topic", c->topic,
                  "Bags (.bag, .db3, .mcap): the LaserScan topic (default: the only one)");
  cmd->add_option("--config", c->config_file,
                  "JSON configuration (as written to RUNDIR/config.json); options given here win");
  add_config_options(cmd, c->run);
  cmd->get_option("--method")->description("One of: " + registration_2d_method_list());
  cmd->add_option("--initial", c->initial, "Initial guess: constant-velocity or identity")
      ->capture_default_str();
  cmd->add_option("--search-angle", c->search_angle_deg, "Correlative search, +- deg")
      ->capture_default_str();
  cmd->add_option("--wide-search-angle", c->wide_search_angle_deg,
                  "Search again over +- this many deg where few points fit (0: off)")
      ->capture_default_str();
  cmd->add_option("--keyframe-angle", c->keyframe_angle_deg,
                  "New keyframe after this many deg of turn (0: not by angle)")
      ->capture_default_str();
  cmd->add_option("--scans", c->scans, "Process at most this many scans (0: all)");
  cmd->add_option("--first-scan", c->first_scan,
                  "Start at this scan (0-based), skipping the ones before it: a part of a log "
                  "(its reference is then measured on that part alone)");
  cmd->add_option("--seed", c->seed, "Seed of sim: sequences")->capture_default_str();
  cmd->add_flag("--no-motion-distortion", c->no_motion_distortion,
                "sim: sequences: measure each scan from its start pose");
  cmd->add_option("--rotation-period", c->rotation_period,
                  "s per turn of the laser, for deskewing (default: the simulated sensor's; "
                  "unknown for logs, so they are not deskewed)");
  cmd->add_flag("--no-return-reading,!--range-codes-as-points", c->infer_no_return,
                "CARMEN FLASER logs: the reading the log's far end repeats (a laser's in-range "
                "no-return code, 51.15 m on acapulco) is no return (the default), or points");
  cmd->add_flag("--quiet", c->run.quiet, "No progress and no summary lines");
  cmd->callback([c, cmd] {
    Map2DRunOptions run = configuration(*c, *cmd);
    SequenceOptions input_options;
    input_options.topic = c->topic;
    input_options.infer_no_return = c->infer_no_return;
    input_options.simulator.seed = c->seed;
    input_options.simulator.motion_distortion = !c->no_motion_distortion;
    Scans2D input =
        load_scans_2d(c->sequence, input_options, c->scans > 0 ? c->first_scan + c->scans : 0);
    if (c->first_scan > 0) {
      if (c->first_scan >= input.scans.size())
        throw Error(fmt::format("map2d: {}: --first-scan {} but it has {} scans", c->sequence,
                                c->first_scan, input.scans.size()));
      input.scans.erase(input.scans.begin(),
                        input.scans.begin() + static_cast<std::ptrdiff_t>(c->first_scan));
      input.description += fmt::format(" (from scan {})", c->first_scan);
    }
    if (c->rotation_period >= 0.0) input.rotation_period = c->rotation_period;
    Map2DSummary s;
    {
      const InterruptFlag interrupt;
      run.stop = interrupt.flag();
      s = run_map2d(input, c->out, run);
    }
    if (!c->run.quiet) {
      fmt::print(
          "map2d {}: {} scans, {} bridged, {} open steps taken from the motion prior, {:.2f} ms "
          "per scan ({:.0f} scans/s){}\n",
          run.mapper.registration.method, s.scans, s.bridged, s.open_steps_from_prior, s.mean_ms,
          s.scans_per_second, s.interrupted ? ", interrupted" : "");
      for (const RelativeError2D* e : {&s.one_step, &s.ten_steps})
        if (e->pairs > 0)
          fmt::print(
              "relative error over {:>2} scans: mean {:.0f} mm / {:.2f} deg, median {:.0f} mm / "
              "{:.2f} deg, failures {:.1f} %\n",
              e->step, 1000 * e->mean_translation, e->mean_rotation * 180 / M_PI,
              1000 * e->median_translation, e->median_rotation * 180 / M_PI, 100 * e->failure_rate);
      const auto print_ate = [](const char* what, const AbsoluteError2D& ate,
                                const RelativeError2D& all_pairs) {
        if (ate.poses > 0)
          fmt::print(
              "ATE (SE(2)-aligned) {}: rmse {:.3f} m, max {:.3f} m; all pairs: {:.3f} m, {:.2f} "
              "deg mean\n",
              what, ate.rmse, ate.max, all_pairs.mean_translation,
              all_pairs.mean_rotation * 180 / M_PI);
      };
      print_ate("of the odometry", s.ate_odometry, s.all_pairs_odometry);
      if (s.loop_closure) {
        const auto& l = *s.loop_closure;
        fmt::print(
            "loop closure: {} keyframes, {} candidates, {} verified, {} accepted ({} outliers), "
            "{:.2f} ms per scan {}; the run took {:.2f} ms per scan{}\n",
            l.counts.keyframes, l.counts.candidates, l.counts.verified, l.accepted,
            l.counts.outliers, l.ms_per_item, l.thread ? "on its own thread" : "inline",
            s.wall_ms_per_scan,
            l.thread ? fmt::format(", {:.2f} of it waiting for loop closure", l.wait_ms_per_item)
                     : std::string());
        print_ate("loop-closed", s.ate_optimized, s.all_pairs_optimized);
      }
      if (s.map_agreement >= 0)
        fmt::print("map agreement with map_reference (2 cells): {:.3f}{}\n", s.map_agreement,
                   s.map_agreement_odometry >= 0
                       ? fmt::format(" (odometry map {:.3f})", s.map_agreement_odometry)
                       : "");
      if (s.consistency_odometry.revisited > 0) {
        const RevisitConsistency2D& shown =
            s.loop_closure ? s.consistency_optimized : s.consistency_odometry;
        std::string others;
        if (s.loop_closure)
          others += fmt::format("odometry {:.1f} cm", 100 * s.consistency_odometry.mean);
        if (s.consistency_reference.revisited > 0)
          others += fmt::format("{}reference poses {:.1f} cm", others.empty() ? "" : ", ",
                                100 * s.consistency_reference.mean);
        fmt::print(
            "revisit consistency (no reference needed): walls of revisits {:.1f} cm apart, mean "
            "over {:.0f} % of the points{}\n",
            100 * shown.mean,
            100.0 * static_cast<double>(shown.revisited) / static_cast<double>(shown.points),
            others.empty() ? "" : " (" + others + ")");
      }
      if (!s.map_error.empty()) fmt::print("no map written: {}\n", s.map_error);
      fmt::print("run folder: {}\n", c->out);
    }
    if (s.interrupted) throw CLI::RuntimeError(130);
  });
}

}  // namespace scanmatch::cli
