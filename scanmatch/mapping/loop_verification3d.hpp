#pragma once
// Verifying a 3D loop candidate: do two keyframe submaps show the same place? A coarse NDT
// registration then a fine GICP one (registration/methods.hpp) from the relative pose the
// candidate implies, then overlap checks both ways: the share of each submap's points that lie
// close to the other's tangent planes and their mean plane distance, and whether the paired
// surfaces' normals constrain all three translation directions. Submaps verified more than once
// are passed as PreparedClouds, which keep what the stages build from them.

#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <string>

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/core/se3.hpp"
#include "scanmatch/mapping/loop_verification.hpp"
#include "scanmatch/registration/prepared_cloud.hpp"

namespace scanmatch {

struct LoopVerification3DOptions : LoopVerificationOptions {
  /// The shared thresholds (loop_verification.hpp) at a submap's scale: a point is paired with
  /// the other submap's nearest point within 1 m, and agrees when it also lies within
  /// `plane_distance` of that point's tangent plane; the agreeing points' mean plane distance at
  /// most 0.08 m; the normals (from the other submap's neighbourhoods) give the weakest
  /// translation direction a share of 0.03 at least; 100 points in each submap.
  LoopVerification3DOptions()
      : LoopVerificationOptions{
            .pair_distance = 1.0, .max_error = 0.08, .min_constraint = 0.03, .min_points = 100} {}

  /// Coarse stage: NDT on a wide grid converges from metres away (the descriptor's start has no
  /// translation at all).
  std::string coarse_method = "ndt";
  double coarse_resolution = 2.0;  ///< m, the coarse method's voxel grid
  /// The coarse stage registers the current submap downsampled to this voxel (m; 0: every point):
  /// a 2 m grid's Gaussians need no more than a point per metre to pull.
  double coarse_source_voxel = 0.5;
  /// With an expectation (LoopExpectation), a candidate whose coarse pose lies farther than its
  /// radius plus this (m) from the expected translation is rejected before the fine stage: the
  /// fine stage moves an accepted loop's pose by centimetres (at most 0.11 m on avia_hku1), while
  /// it would take metres to end within the radius.
  double fine_reach = 2.0;
  /// Fine stage: a point-based method from the coarse result.
  std::string fine_method = "gicp";
  double fine_max_correspondence_distance = 1.0;  ///< m
  int max_iterations = 30;                        ///< of each stage
  /// A paired point agrees when it lies within this distance (m) of the other point's tangent
  /// plane (downsampled submaps sample a surface at different spots: the plane distance shows
  /// whether they agree, the point distance mostly shows the voxel).
  double plane_distance = 0.2;
  /// Accepted only when at least this share of each submap's points agrees with the other
  /// (checked both ways, so a small submap inside a larger one does not pass).
  double min_overlap = 0.5;
};

/// The result of verifying one candidate: `transform` maps current points into the candidate's
/// frame (the loop edge's measurement T_candidate^-1 T_current).
struct LoopVerification3D {
  bool accepted = false;
  /// Rejected by a cheap pre-check before the fine stage (too little of either submap shares a
  /// cell with the other at the coarse pose, or the coarse pose lies beyond an expectation's
  /// reach); the measures below are then unset.
  bool prechecked_out = false;
  /// Of those, rejected because the coarse pose lay beyond the expectation's reach (fine_reach).
  bool beyond_expectation = false;
  Pose transform = Pose::Identity();
  double overlap = 0.0;     ///< the smaller agreeing share of the two ways
  double error = 0.0;       ///< m, mean plane distance of the agreeing points (worse way)
  double constraint = 0.0;  ///< the weakest translation direction's share of the normals
  /// The fine registration's Hessian at the solution, in the pose graph's order (translation,
  /// rotation); zero when there was none.
  Matrix6d hessian = Matrix6d::Zero();
};

/// Where an estimate expects a loop: the current submap's translation in the candidate's frame,
/// and how far from it (m) an accepted loop may end (LoopClosure3D's max_correction).
struct LoopExpectation {
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  double radius = 0.0;
};

/// Verifies that `current` and `candidate` (submaps in their own keyframe frames) show the same
/// place, starting from `initial` (current in the candidate's frame). Never throws for bad clouds
/// (too few or non-finite points) or failed registrations: rejects.
LoopVerification3D verify_loop_3d(const PointCloud& current, const PointCloud& candidate,
                                  const Pose& initial, const LoopVerification3DOptions& options);
/// The same with the submaps' structures (the coarse method's voxel map, k-d trees, the fine
/// method's covariances, normals) kept in `current` and `candidate`: built on first use and reused
/// by later verifications of either submap, with the same result. With `expected`, the coarse
/// pose must also lie within its reach (fine_reach).
LoopVerification3D verify_loop_3d(PreparedCloud& current, PreparedCloud& candidate,
                                  const Pose& initial, const LoopVerification3DOptions& options,
                                  const std::optional<LoopExpectation>& expected = std::nullopt);

}  // namespace scanmatch
