#pragma once
// Verifying a 3D loop candidate: do two keyframe submaps show the same place? A coarse NDT
// registration then a fine GICP one (registration/methods.hpp) from the relative pose the
// candidate implies, then overlap checks both ways: the share of each submap's points that lie
// close to the other's tangent planes and their mean plane distance, and whether the paired
// surfaces' normals constrain all three translation directions.

#include <cstddef>
#include <string>

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/core/se3.hpp"

namespace scanmatch {

struct LoopVerification3DOptions {
  /// Coarse stage: NDT on a wide grid converges from metres away (the descriptor's start has no
  /// translation at all).
  std::string coarse_method = "ndt";
  double coarse_resolution = 2.0;  ///< m, the coarse method's voxel grid
  /// Fine stage: a point-based method from the coarse result.
  std::string fine_method = "gicp";
  double fine_max_correspondence_distance = 1.0;  ///< m
  int max_iterations = 30;                        ///< of each stage
  /// A point is paired with the other submap's nearest point within `pair_distance` (m) after
  /// the registration, and agrees when it lies within `plane_distance` (m) of that point's tangent
  /// plane (downsampled submaps sample a surface at different spots: the plane distance shows
  /// whether they agree, the point distance mostly shows the voxel).
  double pair_distance = 1.0;
  double plane_distance = 0.2;
  /// Accepted only when at least this share of each submap's points agrees with the other
  /// (checked both ways, so a small submap inside a larger one does not pass) ...
  double min_overlap = 0.5;
  /// ... and the agreeing points' mean plane distance is below this, m.
  double max_error = 0.08;
  /// Degeneracy: the smallest eigenvalue of the paired points' mean n n^T (normals from the other
  /// submap's neighbourhoods; eigenvalues sum to 1) must reach this. A tunnel or a corridor gives
  /// ~0 along its axis and would slide to wherever the registration stopped.
  double min_constraint = 0.03;
  std::size_t min_points = 100;  ///< each submap needs this many points to be verified at all
};

/// The result of verifying one candidate: `transform` maps current points into the candidate's
/// frame (the loop edge's measurement T_candidate^-1 T_current).
struct LoopVerification3D {
  bool accepted = false;
  Pose transform = Pose::Identity();
  double overlap = 0.0;     ///< the smaller agreeing share of the two ways
  double error = 0.0;       ///< m, mean plane distance of the agreeing points (worse way)
  double constraint = 0.0;  ///< the weakest translation direction's share of the normals
  /// The fine registration's Hessian at the solution, in the pose graph's order (translation,
  /// rotation); zero when there was none.
  Matrix6d hessian = Matrix6d::Zero();
};

/// Verifies that `current` and `candidate` (submaps in their own keyframe frames) show the same
/// place, starting from `initial` (current in the candidate's frame). Never throws for bad clouds
/// (too few or non-finite points) or failed registrations: rejects.
LoopVerification3D verify_loop_3d(const PointCloud& current, const PointCloud& candidate,
                                  const Pose& initial, const LoopVerification3DOptions& options);

}  // namespace scanmatch
