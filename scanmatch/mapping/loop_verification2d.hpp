#pragma once
// Verifying a 2D loop candidate: do two scans show the same place? A correlative search
// (correlative_search.hpp) around the relative pose the candidate implies, the registration method
// from its result, then overlap checks both ways: the share of each scan's points that land within
// `pair_distance` of the other's surfaces and their mean distance, the points that lie in space the
// other scan saw empty (free space), and whether the paired surfaces' normals constrain every
// direction. A match that leaves one direction open (a corridor) may be accepted as sliding.

#include <cmath>
#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "scanmatch/core/scan2d.hpp"
#include "scanmatch/mapping/loop_verification.hpp"

namespace scanmatch {

struct LoopVerification2DOptions : LoopVerificationOptions {
  /// The shared thresholds (loop_verification.hpp) at a laser's scale: a current point is paired
  /// when a candidate point lies within 0.1 m; their mean distance at most 0.04 m, checked both
  /// ways (current onto candidate and back) like the paired share below; the normals (from beam
  /// neighbours) give the weaker direction a share of 0.1 at least (a corridor's two walls give ~0
  /// and slide along it to wherever the search window allows); 40 points in each scan.
  LoopVerification2DOptions()
      : LoopVerificationOptions{
            .pair_distance = 0.1, .max_error = 0.04, .min_constraint = 0.1, .min_points = 40} {}

  std::string method = "pl-icp";  ///< registration_2d_methods() name of the fine stage
  /// Correlative search around the candidate's implied relative pose: +- m in x and y, +- rad.
  double search_window = 2.0;
  double search_angle = 30.0 * M_PI / 180;
  /// m; 0.1 found the same loops on the CARMEN logs as 0.05, 3.6x faster (the fine stage refines).
  double search_resolution = 0.1;
  /// The search gives up (rejects) where no pose scores this share of its best possible
  /// (correlative_match): most candidates show another place, and ending their search early
  /// halves loop closure's time. Accepted loops on the CARMEN logs scored 0.39 to 1 (5 % below
  /// 0.54 to 0.60); 0: every candidate is searched through.
  double min_search_score = 0.5;
  double max_correspondence_distance = 0.3;  ///< m, of the fine stage
  /// Accepted only when at least this share of the current points is paired (repeated structure
  /// aligns partly; the same place aligns nearly everywhere the views overlap), checked both ways
  /// so that a small scan inside a larger one does not pass.
  double min_paired_fraction = 0.65;
  /// Negative evidence: a point of one scan that lies more than `free_margin` (m) in front of
  /// what the other scan saw along the same bearing sits in space the other saw empty. Different
  /// places that share a few walls put many points there; more than this share (either way)
  /// rejects.
  double free_margin = 0.3;
  double max_free_violations = 0.05;
  /// Rejected when the current scan, slid 1 to 3 m along the match's least determined direction,
  /// keeps more than this share of its paired points (an ambiguous place: a corridor with doors at
  /// even spacing). 0: not checked.
  double max_shifted_fraction = 0.8;
  /// A match that fits (paired share, error, free space) but leaves one translation direction
  /// open (a weak constraint, or the shift test above) is accepted as sliding: its loop edge holds
  /// the heading and the translation across that direction, and along it only a share of what
  /// the match found (LoopClosure2DOptions::sliding_information_kept). A corridor revisited holds
  /// little else, and without such edges a whole traversal can sit 0.2 m across from the
  /// walls it saw before (ACES's diagonal corridor, scans 264-278). false: rejected instead.
  bool accept_sliding = true;
};

/// The result of verifying one candidate: `transform` maps current points into the candidate's
/// frame (the loop edge's measurement T_candidate^-1 T_current).
struct LoopVerification2D {
  bool accepted = false;
  Pose2 transform = Pose2::Identity();
  double paired_fraction = 0.0;
  double error = 0.0;            ///< m, mean distance of the paired points
  double free_violations = 0.0;  ///< share of points in the other scan's free space (worst way)
  double constraint = 0.0;       ///< the weaker direction's share of the normals (worst way)
  double search_score = 0.0;     ///< the correlative search's best score (share of its best)
  /// Gauss-Newton Hessian of the current scan's paired point-to-line distances at `transform`, in
  /// (x, y, theta) of the current scan's frame (unscaled: the information's shape).
  Eigen::Matrix3d hessian = Eigen::Matrix3d::Zero();
  /// The largest share of the paired points kept when slid along the weak direction (when checked).
  double shifted_fraction = 0.0;
  /// Accepted as sliding (accept_sliding): the translation along `slide_direction` (a unit vector
  /// in the current scan's frame, the first fit's weakest translation) is undetermined. The checks
  /// and the Hessian above are then those at the anchored fit, but for paired_fraction: the first
  /// fit's.
  bool sliding = false;
  Eigen::Vector2d slide_direction = Eigen::Vector2d::Zero();
};

/// A scan and the pose it was taken from, in the frame of the scan it is joined to.
struct PosedScan2D {
  const Scan2D* scan = nullptr;
  Pose2 pose = Pose2::Identity();
};

/// The current scan of verify_loop_2d with what the checks build of it (its filled surfaces, their
/// grid, the free space it saw), prepared once for all of its candidates. Holds a copy of the
/// scan; `options` must be those of the verifications it is used in.
class LoopCurrent2D {
 public:
  LoopCurrent2D(const Scan2D& scan, const LoopVerification2DOptions& options);
  ~LoopCurrent2D();
  LoopCurrent2D(const LoopCurrent2D&) = delete;
  LoopCurrent2D& operator=(const LoopCurrent2D&) = delete;

  struct Impl;
  const Impl& impl() const { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

/// A candidate scan joined by its neighbours (posed in its frame) as verify_loop_2d registers and
/// checks against it: the joined scan, its k-d tree and fitted lines, its filled surfaces and the
/// free space each scan saw, each made on first use and then kept for every current scan verified
/// against it. Holds copies of the scans (the neighbours' poses are fixed at construction);
/// `options` must be those of the verifications it is used in.
class LoopReference2D {
 public:
  LoopReference2D(const Scan2D& candidate, const std::vector<PosedScan2D>& candidate_neighbours,
                  const LoopVerification2DOptions& options);
  ~LoopReference2D();
  LoopReference2D(const LoopReference2D&) = delete;
  LoopReference2D& operator=(const LoopReference2D&) = delete;

  struct Impl;
  const Impl& impl() const { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

/// The mean distance (m) of `from`'s points moved by `T` to `onto`'s filled surfaces, over those
/// within `pair_distance` (the verification's `error`, one way); negative when none pair.
double pairing_error_2d(const Scan2D& from, const Scan2D& onto, const Pose2& T,
                        double pair_distance);

/// Verifies that `current` and `candidate` show the same place, starting from `initial` (current
/// in the candidate's frame). Never throws for bad scans (too few or non-finite points): rejects.
/// With `candidate_neighbours` (scans taken near the candidate, posed in its frame) the current
/// scan is registered onto and paired against the candidate joined by them, whose wider view a
/// 180-degree scan revisiting a place from elsewhere overlaps; the way back (candidate onto
/// current) then checks only the error and the free space, not the paired share. The free space
/// is what each of those scans saw from where it was taken. A sliding match (accept_sliding) is
/// fitted again from `anchor`'s position along its open direction (default: `initial`'s), and
/// must fit there too.
LoopVerification2D verify_loop_2d(const Scan2D& current, const Scan2D& candidate,
                                  const Pose2& initial, const LoopVerification2DOptions& options,
                                  const std::vector<PosedScan2D>& candidate_neighbours = {},
                                  const std::optional<Pose2>& anchor = std::nullopt);
/// verify_loop_2d with both sides prepared: the same result, without building them again.
LoopVerification2D verify_loop_2d(const LoopCurrent2D& current, const LoopReference2D& candidate,
                                  const Pose2& initial, const LoopVerification2DOptions& options,
                                  const std::optional<Pose2>& anchor = std::nullopt);

}  // namespace scanmatch
