#pragma once
// Reading a run folder written by `scanmatch odometry` (odometry_run.hpp documents the files) or
// `scanmatch map2d` (map2d_run.hpp): the poses, the per-frame or per-scan statistics
// (timing.csv), the summary and the ground truth written beside them. summary.json's "kind" says
// which run it is (run_record.hpp); a folder without it (written before it existed, or a run that
// never finished) is a map2d run when its timing.csv has no total_ms column.

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "scanmatch/io/trajectory.hpp"
#include "scanmatch/mapping2d/scan2d_stats.hpp"
#include "scanmatch/odometry/frame_stats.hpp"

namespace scanmatch {

struct RunFolder {
  std::string path;
  std::string kind = "odometry";           ///< "odometry" or "map2d" (run_record.hpp)
  std::string method = "?";                ///< from summary.json ("?" when absent)
  std::string label;                       ///< the folder's name
  Trajectory poses;                        ///< poses.txt (or poses_tum.txt)
  std::optional<Trajectory> ground_truth;  ///< poses_gt.txt when present
  std::vector<FrameRecord> timing;         ///< timing.csv of an odometry run, empty when absent
  /// timing.csv of a map2d run (empty when absent, and for folders written before it had an
  /// index and timestamp column: "scan,ms,...").
  std::vector<TimingRow<Scan2DStats>> scan_timing;
  double frames_per_second = 0;  ///< from summary.json
  bool interrupted = false;
  bool has_map = false;  ///< map.pcd present
  /// Loop closure (`--loop-closure`): poses_optimized_tum.txt (or poses_optimized.txt), and the
  /// accepted loop edges of loops.json as (older frame, newer frame) index pairs.
  std::optional<Trajectory> optimized;
  std::vector<std::pair<std::size_t, std::size_t>> loops;
};

/// Throws Error naming the folder and file when poses are missing or a file is malformed.
RunFolder read_run_folder(const std::string& path);

}  // namespace scanmatch
