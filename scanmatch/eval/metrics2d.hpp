#pragma once
// Relative pose error of 2D trajectories over a fixed number of scan steps, as used for the
// CARMEN logs, whose corrected poses are a reference for relative motion only.

#include <cstddef>
#include <vector>

#include "scanmatch/core/scan2d.hpp"

namespace scanmatch {

struct RelativeError2D {
  std::size_t step = 1, pairs = 0;
  double mean_translation = 0, median_translation = 0, max_translation = 0;  ///< m
  double mean_rotation = 0, median_rotation = 0, max_rotation = 0;           ///< rad
  /// Fraction of pairs off by more than the failure thresholds.
  double failure_rate = 0;
};

/// Compares the motion from pose k to pose k + step of `estimate` with that of `reference`, for
/// every k. Throws Error when the sizes differ.
RelativeError2D relative_pose_error_2d(const std::vector<Pose2>& reference,
                                       const std::vector<Pose2>& estimate, std::size_t step,
                                       double failure_translation = 0.2,
                                       double failure_rotation = 5.0 * M_PI / 180);

/// The relative error over all pairs of poses (j > k), the measure of Kuemmerle et al. (2009)
/// with every pair as a relation; `step` is 0. Longer logs are thinned evenly to `max_poses`
/// poses first (the pairs grow with the square). Throws Error when the sizes differ.
RelativeError2D all_pairs_relative_error_2d(const std::vector<Pose2>& reference,
                                            const std::vector<Pose2>& estimate,
                                            std::size_t max_poses = 1500,
                                            double failure_translation = 0.2,
                                            double failure_rotation = 5.0 * M_PI / 180);

/// Absolute trajectory error of positions after the rigid 2D motion (rotation and translation,
/// least squares) that best aligns `estimate` onto `reference`.
struct AbsoluteError2D {
  std::size_t poses = 0;
  double rmse = 0, mean = 0, max = 0;   ///< m
  Pose2 alignment = Pose2::Identity();  ///< maps estimated positions onto the reference
};
/// Throws Error when the sizes differ; zero error for fewer than two poses.
AbsoluteError2D absolute_trajectory_error_2d(const std::vector<Pose2>& reference,
                                             const std::vector<Pose2>& estimate);

/// How well the scans agree where the sensor came back, measured without a reference: a wall
/// seen twice lies double in the map by as much as the two visits disagree. Each point (or every
/// n-th, to look at most at `max_queries`) is compared with the nearest point of another visit,
/// a scan at least `revisit_gap` scans away: its distance to that scan's surface there (the
/// segments to the point's beam neighbours, as the 2D fit check measures), capped at
/// `max_distance`. Points with no other visit's point within `max_distance` do not count, nor
/// points not finite or 10^9 times max_distance away (a diverged run). The poses' own noise and
/// sparse far samples set a floor (means of 2-7 cm with the Radish logs' corrected poses).
struct RevisitConsistency2D {
  std::size_t points = 0;     ///< points looked at
  std::size_t revisited = 0;  ///< of those, with another visit's point within max_distance
  double mean = 0, median = 0, p90 = 0;  ///< m, over the revisited points
};
/// `poses[i]` is the pose of `scans[i]` (points in the laser frame). Throws Error when the sizes
/// differ, the gap is 0 or the distance not positive.
RevisitConsistency2D revisit_consistency_2d(const std::vector<Scan2D>& scans,
                                            const std::vector<Pose2>& poses,
                                            std::size_t revisit_gap = 20, double max_distance = 0.5,
                                            std::size_t max_queries = 200000);

}  // namespace scanmatch
