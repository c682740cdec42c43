#pragma once
// `scanmatch map2d` as a library call: 2D scans from a CARMEN log, a simulated data set or
// `sim:PRESET`, chained scan to scan by Mapper2D, written as a run folder with an occupancy grid.

#include <atomic>
#include <optional>
#include <string>
#include <vector>

#include "scanmatch/eval/metrics2d.hpp"
#include "scanmatch/mapping/loop_closure2d.hpp"
#include "scanmatch/mapping2d/grid_map.hpp"
#include "scanmatch/mapping2d/mapper2d.hpp"
#include "scanmatch/run/loop_closure_run.hpp"
#include "scanmatch/sim/open_scans_2d.hpp"

namespace scanmatch {

struct Map2DRunOptions {
  Mapper2DConfig mapper;
  GridMapOptions grid;
  /// No-return beams mark free space out to this range, m (0: none, the default: a dropout looks
  /// like a no-return beam, and its free ray would cut through the wall it missed).
  double miss_range = 0.0;
  bool reference_map = false;  ///< also map_reference.{pgm,yaml,png} from the reference poses
  /// 2D loop closure (mapping/loop_closure2d.hpp) over the odometry: poses_optimized_tum.txt,
  /// loops.json, map.* from the optimized poses (the odometry's map becomes map_odometry.*).
  bool loop_closure = false;
  LoopClosure2DOptions loop;  ///< its settings (config.json's "loop")
  /// Loop closure runs on its own thread beside the odometry (which never needs its result), fed
  /// in scan order: the same poses and loops as inline, and the odometry does not wait for it
  /// where a second core is free.
  bool loop_closure_thread = true;
  bool quiet = false;
  const std::atomic<bool>* stop = nullptr;  ///< set to end early (Ctrl-C); what is done is kept
};

struct Map2DSummary {
  std::size_t scans = 0, bridged = 0;
  std::size_t open_steps_from_prior = 0;  ///< steps the motion prior chose (open_step_window)
  double mean_ms = 0, max_ms = 0, scans_per_second = 0;
  bool interrupted = false, has_reference = false;
  RelativeError2D one_step, ten_steps;
  /// SE(2)-aligned absolute error against the reference: of the odometry, and of the optimized
  /// poses when loop closure ran.
  AbsoluteError2D ate_odometry, ate_optimized;
  /// The relative error over all pairs of poses (all_pairs_relative_error_2d), likewise.
  RelativeError2D all_pairs_odometry, all_pairs_optimized;
  /// With loop closure: its counts, accepted loops and times per scan (summary.json's
  /// "loop_closure"); absent without.
  std::optional<LoopClosureRecord<LoopClosure2DCounts>> loop_closure;
  /// The run's time per scan from the first scan until loop closure has caught up (no map
  /// writing): what loop closure adds shows as the difference to the same run without it.
  double wall_ms_per_scan = 0;
  /// Share of the map's occupied cells within two cells of an occupied cell of map_reference
  /// (negative: not computed; needs reference_map), for map.* and (with loop closure) the
  /// odometry's map.
  double map_agreement = -1, map_agreement_odometry = -1;
  /// How far apart revisits' walls lie (revisit_consistency_2d; needs no reference): for the
  /// optimized poses with loop closure (else unset), the odometry's and (with a reference) the
  /// reference poses'.
  RevisitConsistency2D consistency_optimized, consistency_odometry, consistency_reference;
  /// Why map.* (or map_reference.*) was not written, e.g. a trajectory too large for the grid.
  std::string map_error, reference_map_error;
};

/// Writes RUNDIR/poses_tum.txt and timing.csv (flushed per scan: index, timestamp and the fields
/// of Scan2DStats' description, mapping2d/scan2d_stats.hpp), poses_reference_tum.txt,
/// summary.json ("kind": "map2d"; "options" as config.json), config.json (the options, for
/// `map2d --config`) and
/// map.{pgm,yaml,png}
/// (atomically); with loop_closure also poses_optimized_tum.txt, loops.json and
/// map_odometry.{pgm,yaml,png}.
Map2DSummary run_map2d(const Scans2D& input, const std::string& run_folder,
                       const Map2DRunOptions& options);

}  // namespace scanmatch
