#pragma once
// Reading a run folder written by `scanmatch odometry` (run.hpp documents the files): the poses,
// the per-frame statistics (timing.csv), the summary and the ground truth written beside them.

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "scanmatch/io/trajectory.hpp"
#include "scanmatch/odometry/frame_stats.hpp"

namespace scanmatch {

struct RunFolder {
  std::string path;
  std::string method = "?";                ///< from summary.json ("?" when absent)
  std::string label;                       ///< the folder's name
  Trajectory poses;                        ///< poses.txt (or poses_tum.txt)
  std::optional<Trajectory> ground_truth;  ///< poses_gt.txt when present
  std::vector<FrameRecord> timing;         ///< timing.csv, empty when absent
  double frames_per_second = 0;            ///< from summary.json
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
