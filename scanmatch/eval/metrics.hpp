#pragma once
// Trajectory accuracy metrics: ATE (with optional SE(3)/Sim(3) Umeyama alignment), RPE over a
// frame or distance delta, and the KITTI odometry benchmark's drift (its devkit's definition).
// Both trajectories must already be associated: pose i of one belongs with pose i of the other.

#include <cstddef>
#include <string>
#include <vector>

#include "scanmatch/core/alignment.hpp"
#include "scanmatch/core/se3.hpp"
#include "scanmatch/core/statistics.hpp"
#include "scanmatch/io/trajectory.hpp"

namespace scanmatch {

enum class Alignment { kNone, kSe3, kSim3 };
Alignment parse_alignment(const std::string& name);  ///< "none", "se3", "sim3"; throws Error
const char* to_string(Alignment alignment);

struct AteResult {
  std::size_t poses = 0;
  double rmse = 0, mean = 0, median = 0, max = 0;  ///< position error, m
  double path_length = 0;                          ///< of the ground truth, m
  double rmse_percent_of_path = 0;                 ///< rmse / path length * 100 (0 if still)
  double final_drift = 0;  ///< position error of the last pose, m (useful for a still sensor)
  Similarity alignment;    ///< what was applied to the estimate
};
AteResult compute_ate(const std::vector<Pose>& ground_truth, const std::vector<Pose>& estimate,
                      Alignment alignment = Alignment::kNone);

struct RpeResult {
  std::size_t pairs = 0;
  double translation_rmse = 0, translation_mean = 0, translation_median = 0;  ///< m
  double rotation_rmse = 0, rotation_mean = 0;                                ///< deg
};
/// The error of each relative motion between poses `delta` frames apart, in order: entry k is
/// that of pose k to pose k + delta (`ground_truth.size() - delta` entries). The per-step view of
/// compute_rpe_frames, for plotting where along a run the error arises.
struct RelativeErrors {
  std::vector<double> translation;  ///< m
  std::vector<double> rotation;     ///< deg
};
RelativeErrors relative_errors(const std::vector<Pose>& ground_truth,
                               const std::vector<Pose>& estimate, std::size_t delta = 1);

/// Relative pose error between poses `delta` frames apart.
RpeResult compute_rpe_frames(const std::vector<Pose>& ground_truth,
                             const std::vector<Pose>& estimate, std::size_t delta);
/// Relative pose error between each pose and the first one at least `distance` metres further
/// along the ground-truth path.
RpeResult compute_rpe_distance(const std::vector<Pose>& ground_truth,
                               const std::vector<Pose>& estimate, double distance);

struct KittiDriftResult {
  std::size_t segments = 0;          ///< number of evaluated (start, length) segments
  double translation_percent = 0;    ///< average translational error, %
  double rotation_deg_per_100m = 0;  ///< average rotational error, deg / 100 m
  std::vector<double> lengths_used;  ///< segment lengths the path allowed (of 100..800 m)
};
/// KITTI devkit: segments of 100, 200, ..., 800 m starting every 10th frame; error of the relative
/// motion over the segment divided by its length; averaged over all segments.
KittiDriftResult compute_kitti_drift(const std::vector<Pose>& ground_truth,
                                     const std::vector<Pose>& estimate);

/// Cumulative ground-truth distance at each pose (first entry 0).
std::vector<double> cumulative_distances(const std::vector<Pose>& poses);

struct Association {
  std::vector<Pose> ground_truth, estimate;  ///< paired poses
  std::vector<double> timestamps;            ///< of the pairs, when associated by time
  std::vector<std::size_t> estimate_index;   ///< of each pair in the estimate trajectory
  bool by_timestamp = false;
  std::string description;  ///< e.g. "by index (KITTI files carry no timestamps)"
};
/// Pairs poses by timestamp when both trajectories have them (nearest within `max_time_gap`
/// seconds), by index otherwise. Mismatched lengths are an error unless `allow_partial` (then the
/// common prefix or the matched timestamps are used). Throws Error with a clear message.
Association associate(const Trajectory& ground_truth, const Trajectory& estimate,
                      bool allow_partial = false, double max_time_gap = 0.01);

}  // namespace scanmatch
