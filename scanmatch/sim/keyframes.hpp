#pragma once
// Keyframe data sets from the simulator: a subset of a preset's frames (every Nth, or one each
// time the sensor has moved or turned far enough, as FAST-LIO saves its keyframes), optionally
// thinned to a point budget and without per-point time. The kept frames keep their exact ground
// truth (poses in the world frame of frame 0, which is always kept) and their timestamps.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "scanmatch/sim/simulator.hpp"

namespace scanmatch::sim {

struct KeyframeOptions {
  std::size_t every = 1;      ///< only every Nth frame is a candidate (1: all)
  double distance = 0.0;      ///< m: keep a candidate once the sensor moved this far (0: off)
  double distance_max = 0.0;  ///< m: > distance: a random threshold in [distance, max] per keyframe
  double angle = 0.0;         ///< rad: keep a candidate once the sensor turned this far (0: off)
  std::size_t max_points = 0;  ///< random subsample of each kept frame to this many (0: all)
  bool point_time = true;      ///< false: frames are written without the per-point time field
  std::uint64_t seed = 1;      ///< random thresholds and subsampling

  /// True when the options change anything against writing every frame as it is.
  bool active() const;
};

/// Throws Error for inconsistent options (every 0, negative distances, max below distance).
void check_keyframe_options(const KeyframeOptions& options);

/// Indices of the kept frames, ascending, frame 0 first. A candidate (index a multiple of
/// `every`) is kept when no distance or angle threshold is set, or when the ground-truth motion
/// since the last kept frame reaches the distance or the angle threshold.
std::vector<std::size_t> select_keyframes(const Simulator& simulator,
                                          const KeyframeOptions& options);

/// Applies max_points (a seeded random subset, in the original order) and point_time to frame
/// `index`'s cloud.
PointCloud thin_keyframe(PointCloud cloud, const KeyframeOptions& options, std::size_t index);

/// Writes the kept frames like write_dataset (frames/NNNNNN.pcd named by the original frame index,
/// poses_gt.txt, poses_gt_tum.txt, times.txt) with a "keyframes" object in dataset.json. 3D only.
void write_keyframe_dataset(const Simulator& simulator, const KeyframeOptions& options,
                            const std::string& folder, bool quiet);

}  // namespace scanmatch::sim
