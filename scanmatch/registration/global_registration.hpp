#pragma once
// Global registration: the transform between two clouds with no initial guess, and the evidence
// for it, or a clear "cannot" when the evidence is too weak.
//
// Stages: both clouds voxel-downsampled (`feature_voxel_size`), FPFH descriptors (fpfh.hpp) on
// at most `max_keypoints` points of each, mutual nearest neighbours in descriptor space as
// putative correspondences, then a maximum-clique inlier selection (as in TEASER): two
// correspondences are consistent when they keep the distance between their points within
// `noise_bound`, a rigid motion's correct matches are pairwise consistent, so they form a large
// clique of the consistency graph. Cliques are grown greedily from many seeds; each gives a
// closed-form (Umeyama) hypothesis, re-fitted on every correspondence it explains. The best
// hypothesis must explain `min_inliers` correspondences and clearly more than any different
// motion explains among the rest (ambiguity = second / best; the search for that rival is re-run
// on the correspondences the best leaves unexplained); it is then refined by a local method
// (registration/methods.hpp) and the refined overlap checked.
//
// Use from a pipeline: `register_global(source, target, options)`; when `result.success`, use
// `result.transform` (T_target_source) as the initial guess of the usual stages; otherwise
// `result.failure` says why (and the caller keeps its prior).

#include <cstddef>
#include <optional>
#include <string>

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/core/se3.hpp"
#include "scanmatch/features/fpfh.hpp"
#include "scanmatch/registration/options.hpp"
#include "scanmatch/registration/solver.hpp"

namespace scanmatch {

/// The refinement's defaults: vgicp (1 m voxels), at most 60 iterations.
RegistrationOptions global_refinement_defaults();

struct GlobalRegistrationOptions {
  double feature_voxel_size = 0.5;   ///< m, voxel grid of the keypoints and their neighbourhoods
  std::size_t max_keypoints = 4000;  ///< per cloud; more downsampled points are thinned evenly
  FpfhOptions fpfh;  ///< radius 2.5 m = 5 voxels (its viewpoint is replaced by the two below)
  Eigen::Vector3d source_viewpoint = Eigen::Vector3d::Zero();  ///< sensor position, source frame
  Eigen::Vector3d target_viewpoint = Eigen::Vector3d::Zero();  ///< sensor position, target frame
  double noise_bound = 0.4;        ///< m, largest distance error of a correct correspondence
  std::size_t clique_seeds = 300;  ///< correspondences (highest consistency degree) grown from
  std::size_t min_inliers = 12;    ///< correspondences the best hypothesis must explain
  double max_ambiguity = 0.5;  ///< fail when a different motion explains more than this share of
                               ///< the best's count among the matches the best leaves unexplained
  double distinct_translation = 2.0;  ///< m, hypotheses further apart are different motions
  double distinct_rotation = 10.0 * M_PI / 180;  ///< rad, likewise
  bool refine = true;                            ///< refine the global result with `refinement`
  double refine_voxel_size = 0.25;  ///< m, voxel grid of both clouds for the refinement (0: none)
  RegistrationOptions refinement = global_refinement_defaults();
  double min_overlap = 0.3;  ///< fail below this share of refined source points near the target
  int num_threads = 1;       ///< TBB threads for normals and descriptors
};

struct GlobalRegistrationResult {
  bool success = false;
  std::string failure;                       ///< why not, when !success (one line, for users)
  Pose transform = Pose::Identity();         ///< T_target_source (refined when options.refine)
  Pose coarse_transform = Pose::Identity();  ///< the global stage's estimate before refinement
  std::size_t source_keypoints = 0, target_keypoints = 0;
  std::size_t correspondences = 0;  ///< mutual nearest neighbours in descriptor space
  std::size_t clique_size = 0;      ///< largest consistent set found
  std::size_t inliers = 0;          ///< correspondences the best hypothesis explains
  double inlier_ratio = 0.0;        ///< inliers / correspondences
  std::size_t second_inliers = 0;   ///< matches the best different motion explains and the
                                    ///< best does not
  double ambiguity = 0.0;           ///< second_inliers / inliers
  double overlap = 0.0;  ///< share of (refine-voxel) source points within feature_voxel_size of
                         ///< a target point under the final transform
  double fitness = 0.0;  ///< mean squared distance of those points, m^2
  RegistrationResult refinement;  ///< the local stage's result (when run)
  double feature_ms = 0.0, matching_ms = 0.0, refine_ms = 0.0;

  /// The transform when the registration succeeded.
  std::optional<Pose> accepted() const {
    return success ? std::optional<Pose>(transform) : std::nullopt;
  }
  /// The evidence, "N inliers of M correspondences (...), ambiguity ..., overlap ...", for logs
  /// (the failure, if any, is in `failure`).
  std::string summary() const;
};

/// Registers source onto target with no initial guess. Never throws for weak evidence (the
/// result says it failed and why); throws Error for an empty cloud or invalid options.
GlobalRegistrationResult register_global(const PointCloud& source, const PointCloud& target,
                                         const GlobalRegistrationOptions& options = {});

}  // namespace scanmatch
