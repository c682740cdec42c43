#pragma once
// Runs an odometry pipeline over a whole sequence and writes a run folder (RUNDIR):
//   poses.txt       KITTI rows, one per frame, sensor pose in the world frame of frame 0
//   poses_tum.txt   the same poses as TUM rows (timestamp tx ty tz qx qy qz qw)
//   poses_gt.txt    when the source has ground truth: its poses for the frames run (KITTI rows),
//   poses_gt_tum.txt  and as TUM rows when it has timestamps (written at the end)
//   timing.csv      per frame: index,timestamp, then the FrameStats fields in the order of their
//                   description (frame_stats.hpp): preprocess_ms,coarse_ms,fine_ms,map_ms,total_ms,
//                   points_in,points_downsampled,iterations,condition_number,
//                   degenerate_directions,bridged
//   summary.json    "kind": "odometry" (run_record.hpp), method, options (the whole
//                   configuration), frames, mean and max ms of each stage of frame_stats.hpp,
//                   frames per second, the run's wall ms per frame,
//                   whether the run was interrupted, the error that ended it early, and the ATE
//                   when the source has ground truth (written atomically at the end, also after
//                   such an error)
//   config.json     the OdometryConfig used and the map export options (reloadable with
//                   --config; scanmatch/run/run_config.hpp)
//   map.pcd/.ply    on request: the accumulated registered frames, voxel-downsampled
// With loop closure (RunOptions::loop_closure; mapping/loop_closure3d.hpp) also, at the end:
//   poses_optimized.txt, poses_optimized_tum.txt   the loop-closed poses (KITTI, TUM rows)
//   loops.json      the accepted loop edges: frames, keyframes, the relative pose of the two
//                   frames' poses as poses.txt gives them, overlap, error
//   map.pcd/.ply    on request, rebuilt from the loop-closed poses; the odometry's map becomes
//                   map_odometry.pcd/.ply
//   summary.json    gains "loop_closure" (counts, ms per frame, whether it ran on its own
//                   thread and how long the odometry waited for it), "ate" becomes the
//                   loop-closed poses' and "ate_odometry" the odometry's
// Per-frame files are appended and flushed frame by frame, so an interrupted run keeps its frames.
// Timing covers the pipeline only (register_frame), never reading or simulating the frames; only
// wall_ms_per_frame is the whole run's.

#include <atomic>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "scanmatch/eval/metrics.hpp"
#include "scanmatch/io/sequence.hpp"
#include "scanmatch/mapping/loop_closure3d.hpp"
#include "scanmatch/odometry/odometry.hpp"
#include "scanmatch/run/loop_closure_run.hpp"

namespace scanmatch {

struct RunOptions {
  std::string out_dir;             ///< RUNDIR (created); empty: write nothing
  std::size_t max_frames = 0;      ///< 0: every frame of the source
  bool write_map = false;          ///< write RUNDIR/map.<map_format>
  std::string map_format = "pcd";  ///< "pcd" or "ply"
  double map_voxel_size = 0.1;     ///< m, downsampling of the exported map
  double map_export_radius = 0.0;  ///< m around the last pose; 0: unbounded (the whole run)
  /// A pose graph over keyframes with verified loop edges (mapping/loop_closure3d.hpp), fed each
  /// registered frame; writes the loop-closed poses, loops.json and the map from them.
  bool loop_closure = false;
  LoopClosure3DOptions loop;  ///< its settings (config.json's "loop")
  /// Loop closure runs on its own thread beside the odometry (which never needs its result), fed
  /// in frame order: the same poses, loops and map as inline, and the odometry does not wait for
  /// it where a second core is free.
  bool loop_closure_thread = true;
  bool quiet = false;  ///< no progress line
  /// Set to true (e.g. from a SIGINT handler) to stop after the current frame; the run then
  /// finishes its files and reports interrupted = true.
  const std::atomic<bool>* stop = nullptr;
};

struct RunSummary {
  std::string method;
  std::string source;  ///< SequenceSource::describe()
  std::size_t frames = 0, bridged_frames = 0;
  bool interrupted = false;
  std::string error;  ///< why the source could not deliver a frame (empty: it did not fail)
  /// Every stage of frame_stats.hpp, in its order (zeros before a run).
  std::vector<StageStatistics> stages = stage_statistics({});
  double frames_per_second = 0.0;  ///< 1000 / mean total ms (pipeline time only)
  /// The run's wall time per frame from the first frame until loop closure (if any) has caught up
  /// and finished, reading the frames included, writing the map not: what loop closure adds shows
  /// as the difference to the same run without it.
  double wall_ms_per_frame = 0.0;
  std::vector<double> timestamps;  ///< per frame
  std::vector<Pose> poses;         ///< per frame, world frame of frame 0
  std::vector<FrameStats> stats;   ///< per frame
  /// The source's ground truth for the frames run (empty when it has none), as in poses_gt.txt.
  std::vector<Pose> ground_truth;
  /// ATE of `poses` against `ground_truth`, unaligned (both start at the identity, as the run
  /// does); absent without ground truth or frames.
  std::optional<AteResult> ate;
  /// With loop closure: its counts, accepted loops (not judged outliers at the end) and times per
  /// frame (summary.json's "loop_closure"; absent without), the loop-closed poses per frame and
  /// their ATE (like `ate`).
  std::optional<LoopClosureRecord<LoopClosure3DCounts>> loop_closure;
  std::vector<Pose> optimized_poses;
  std::optional<AteResult> ate_optimized;

  /// The stage named `name` in frame_stats.hpp ("total"); throws std::out_of_range for others.
  const StageStatistics& stage(std::string_view name) const;
};

/// Runs `config` over `source` (from its current position) and writes RUNDIR as described above.
/// Bad frames (empty, unreadable) are reported on stderr and bridged, never fatal; a frame the
/// source cannot deliver at all (Error from next(), e.g. a truncated file) ends the run: RUNDIR
/// is finished for the frames before it (summary.json with "error"), then that Error is thrown.
/// With config.spin_times, frames without point times get them from azimuth (spin_times.hpp)
/// before the odometry sees them.
RunSummary run_odometry(SequenceSource& source, const OdometryConfig& config,
                        const RunOptions& options);

}  // namespace scanmatch
