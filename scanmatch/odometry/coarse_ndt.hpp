#pragma once
// The coarse stage of CTF-ICP: NDT frame-to-frame. The frame, further downsampled to
// coarse_voxel_size, is registered against the previous frame's NDT grid (ndt_resolution,
// Magnusson's score) from the motion prior. Its job is only to bring the fine stage into its basin.
//
// Under an uncertain prior (motion_model.hpp) it also tries other starts: the identity, half and
// twice the prior, and the prior turned about the sensor's z axis by +-k * rotation_start_step
// (a hand-held sweep that reverses leaves the constant-velocity rotation several degrees off, out
// of NDT's basin), each first on a grid uncertain_ndt_scale times wider (with the points thinned to
// start_voxel_size: that descent only has to reach the normal grid's basin), then on the normal
// grid; the start whose result scores best on the normal grid (by a margin) wins. Most starts reach
// the same optimum: a solve that comes `near` an optimum another solve converged to ends there.
// With start_screen_points set and more starts than start_full_solves, the starts are first solved
// on a spread subset of about start_screen_points points and ranked by their score there; only the
// best few that beat the plain result on the subset are solved again on every point (most frames:
// none). A certain prior whose solve took wide_start_iterations or more (slow: it may have stopped
// in a ripple of the grid, as when a car enters a turn) gets the prior itself as the one other
// start; after a long time step (keyframes, MotionPrior::turn_reach) it gets every start, and the
// turned starts reach as far as a vehicle turns in that time.

#include <cstddef>
#include <optional>
#include <vector>

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/geometry/gaussian_voxel_map.hpp"
#include "scanmatch/odometry/motion_model.hpp"
#include "scanmatch/odometry/odometry_config.hpp"
#include "scanmatch/registration/solver.hpp"

namespace scanmatch {

struct KnownOptima;
struct NdtFactor;

struct CoarseResult {
  Pose motion = Pose::Identity();  ///< from the reference frame (the prior when not registered)
  bool registered = false;         ///< enough points found a voxel; false: motion is the prior
  int iterations = 0;              ///< every start's iterations on every coarse point
  int screen_iterations = 0;       ///< the starts' iterations on the ranking subset
  /// Another start beat the prior's own result: the prior was wrong and the frame recovered.
  bool recovered = false;
  double condition_number = 0.0;  ///< of the plain start's information matrix
  /// Under an uncertain prior, the other optima the stage found (the plain result first when
  /// another start won, then the other starts' in the order tried): where to look when `motion`
  /// lies outside the motion gate.
  std::vector<Pose> alternatives;
};

class CoarseNdt {
 public:
  explicit CoarseNdt(const OdometryConfig& config);
  /// The frame's motion from the reference frame. `frame` is the preprocessed frame (the stage
  /// downsamples it further). Without a reference, the prior's motion.
  CoarseResult align(const PointCloud& frame, const MotionPrior& prior) const;
  /// Makes `frame` (preprocessed, in its sensor frame) the next frame's reference. A bridged
  /// frame without points keeps the last reference cloud (the grid is always the new frame's).
  void set_reference(PointCloud frame, bool bridged);
  /// The reference frame's points (the last frame registered).
  const PointCloud& reference() const { return reference_; }

 private:
  /// The other starts under an uncertain prior, `prior_motion` first, with `turned_per_side`
  /// turned starts each way (each also bent along an arc where `along_arc`), none within `near`
  /// of an earlier one.
  std::vector<Pose> distinct_starts(const Pose& prior_motion, int turned_per_side,
                                    bool along_arc) const;
  /// Solves each start (on the wider grid first when `from_wide_grid`, then with `normal`, the
  /// coarse points' factor on the normal grid) and returns the optima not already in `optima`,
  /// adding them there; a solve that reaches a known optimum stops. Adds the iterations.
  std::vector<Pose> solve_starts(const NdtFactor& normal, const std::vector<Pose>& starts,
                                 bool from_wide_grid, KnownOptima& optima, int& iterations) const;
  /// The best of `plain` and `solved` by NDT score (`normal`); another replaces `plain` only when
  /// better by kScoreMargin (then `recovered`).
  Pose best_of(const NdtFactor& normal, const Pose& plain, const std::vector<Pose>& solved,
               bool& recovered) const;
  /// Whether `start_count` starts on `source_points` points are ranked on a subset first.
  bool should_screen(std::size_t start_count, std::size_t source_points) const;
  /// Solves each start (wider grid, then normal grid) on about start_screen_points of `source`
  /// and returns the start_full_solves best results that score better than `plain` there (none:
  /// the plain result stands). They are in the normal grid's basin: solved again on it alone.
  std::vector<Pose> screened_starts(const PointCloud& source, const std::vector<Pose>& starts,
                                    const Pose& plain, int& screen_iterations) const;
  /// reference_'s grid uncertain_ndt_scale times wider: a basin a few times the normal one.
  const GaussianVoxelMap& wide_grid() const;

  OdometryConfig config_;
  SolverOptions solver_;
  GaussianVoxelMap grid_;  ///< the reference frame's NDT grid, in its sensor frame
  PointCloud reference_;
  /// wide_grid(), built on first use (so align() is not safe to call from two threads at once on
  /// one CoarseNdt).
  mutable std::optional<GaussianVoxelMap> wide_grid_;
};

}  // namespace scanmatch
