#pragma once
// 3D loop closure on top of LiDAR odometry: keyframes become nodes of a pose graph
// (pose_graph.hpp) chained by odometry edges; each new keyframe looks for earlier keyframes of the
// same place, verifies every candidate geometrically and adds the verified ones as loop edges,
// then the graph is optimized. The 3D counterpart of loop_closure2d.hpp, with the same structure.
//
// A keyframe's cloud is a small local submap: the last `submap_frames` frames moved into the
// keyframe's frame by the odometry and voxel-downsampled, so that narrow or sparse sensors (a
// Livox Avia sees 70 degrees) still give enough structure, while memory stays bounded by the voxel.
//
// Candidates come from two sources (their union, loop_candidates.hpp): earlier keyframes near the
// new one in the current (optimized) estimate, and the place database (place_database.hpp), both
// skipping the newest `skip_recent` keyframes. Verification (loop_verification3d.hpp) needs
// no prior: it starts from the relative pose the estimate implies (proximity) or from the
// descriptor's yaw (database). A verified loop must also agree with the estimate (repeated
// structure verifies perfectly at the wrong place); the graph's robust kernel and chi-square test
// (PoseGraphConfig) catch what still slips through. This file holds the orchestration: keyframes
// and their submaps, odometry edges, when to search and when to optimize.

#include <cmath>
#include <cstddef>
#include <deque>
#include <list>
#include <memory>
#include <string>
#include <vector>

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/core/se3.hpp"
#include "scanmatch/features/place_database.hpp"
#include "scanmatch/mapping/keyframe_graph.hpp"
#include "scanmatch/mapping/loop_candidates.hpp"
#include "scanmatch/mapping/loop_verification3d.hpp"
#include "scanmatch/mapping/pose_graph.hpp"
#include "scanmatch/registration/prepared_cloud.hpp"

namespace scanmatch {

struct LoopClosure3DOptions {
  /// A new keyframe once the odometry has moved this far from the last one (m or rad).
  double keyframe_distance = 1.0;
  double keyframe_angle = 15.0 * M_PI / 180;
  /// The keyframe's submap: the last this many frames (the keyframe's own included), in its
  /// frame, downsampled to `submap_voxel` m. Frames are kept downsampled to that voxel too, or to
  /// the coarser one the last submap needed to fit `max_submap_points`.
  std::size_t submap_frames = 10;
  double submap_voxel = 0.25;
  /// A submap with more points is downsampled again with a voxel 1.5 times larger, until it
  /// fits: verification's cost (neighbourhoods of every point) and memory grow with the points.
  std::size_t max_submap_points = 8000;
  /// Odometry edges between consecutive keyframes get a fixed diagonal information from these
  /// standard deviations (m per axis, rad per axis): LiDAR odometry over a metre drifts by a few
  /// cm and a fraction of a degree.
  double odometry_sigma_translation = 0.05;
  double odometry_sigma_rotation = 0.5 * M_PI / 180;
  /// Loop edges: the fine registration's Hessian, scaled so that its best-constrained translation
  /// direction has this standard deviation (m): the Hessian's shape says which directions the
  /// geometry pins down, but its scale (thousands of points, GICP's thin plane covariances) would
  /// claim sub-millimetre certainty. Its rotation block's best direction is capped at
  /// `loop_sigma_rotation` (rad): at that scale the lever arm of far points would claim a small
  /// fraction of a degree, more than submaps built from odometry poses hold (a guard: on the
  /// simulated campus loop the cap changed nothing measurable). Without a usable Hessian (not
  /// finite or no positive translation eigenvalue), the fixed diagonal of both sigmas.
  double loop_sigma_translation = 0.05;
  double loop_sigma_rotation = 0.5 * M_PI / 180;
  /// The newest keyframes are never candidates (they are trivially the same place).
  std::size_t skip_recent = 30;
  /// Candidates (loop_candidates.hpp): earlier keyframes within 8 m in the current estimate, the 2
  /// nearest of different visits, and the place database's best match below descriptor distance
  /// 0.3 ...
  LoopCandidateOptions candidates{.proximity_radius = 8.0,
                                  .max_proximity_candidates = 2,
                                  .max_descriptor_distance = 0.3,
                                  .max_descriptor_candidates = 1};
  /// ... taken from its best `descriptor_matches` matches: those the estimate rules out
  /// (registration_reach) are skipped, since look-alike places often match better than the true
  /// one.
  std::size_t descriptor_matches = 5;
  /// Repeated structure verifies perfectly at the wrong place, so a verified loop must also agree
  /// with the current estimate: its translation may differ from the estimate's relative pose by at
  /// most this base (m) plus this share of the odometry path between the two keyframes.
  double max_correction = 2.0;
  double max_correction_per_m = 0.05;
  /// How far (m) verification can move a candidate from its start: a descriptor match whose
  /// start (no translation) lies farther than the gate plus this from the estimate is ruled out
  /// without being verified (verified, it could only be rejected by the gate).
  double registration_reach = 8.0;
  /// Loop edges are looked for at every this-many keyframes (1: each one) ...
  std::size_t search_every = 1;
  /// ... and not at the next this-many keyframes after one that added a loop edge: on a second
  /// pass every keyframe revisits a place, and one loop every few metres holds the graph as well
  /// as one per keyframe at a fraction of the verification cost (0: no pause).
  std::size_t keyframes_between_loops = 4;
  LoopVerification3DOptions verification;
  /// What verification builds from a keyframe's submap (the coarse method's voxel map, k-d tree,
  /// the fine method's covariances, normals: 0.25-2 MB a keyframe) is kept for its next
  /// verifications, the current keyframe's against each candidate and an old keyframe's at every
  /// revisit, up to this many MB; the least recently verified are dropped first (0: the current
  /// keyframe's are kept for its other candidates only). The results are the same either way.
  double verification_memory_mb = 64.0;
  PlaceDescriptorOptions descriptor;
  PoseGraphConfig graph;
};

/// An accepted loop edge.
struct Loop3D {
  std::size_t from_keyframe = 0, to_keyframe = 0;  ///< to is the newer keyframe
  std::size_t from_frame = 0, to_frame = 0;        ///< their indices among all added frames
  Pose relative = Pose::Identity();                ///< to in the frame of from
  double overlap = 0.0, error = 0.0;
  bool outlier = false;  ///< judged an outlier by the graph's last optimize()
};

struct LoopClosure3DCounts {
  std::size_t keyframes = 0;
  std::size_t candidates = 0;  ///< candidate pairs proposed (after merging both sources)
  std::size_t verified = 0;    ///< candidates that passed every check (loop edges added)
  std::size_t rejected_by_verification = 0;
  /// Of those, rejected by verification's pre-check before the fine stage.
  std::size_t prechecked_out = 0;
  /// Of those, rejected because the coarse pose lay beyond the estimate's reach (fine_reach).
  std::size_t beyond_estimate_before_fine = 0;
  /// Keyframe submaps whose verification structures were built (again, when the memory budget
  /// had dropped them): the verification cache's misses.
  std::size_t submaps_prepared = 0;
  /// Verified but too far from the current estimate (max_correction): not added.
  std::size_t rejected_by_estimate = 0;
  /// Place-database matches ruled out before verification (registration_reach); not candidates.
  std::size_t ruled_out_by_estimate = 0;
  std::size_t outliers = 0;  ///< loop edges the graph judged outliers at its last optimize()
  std::size_t optimizations = 0;
  double total_ms = 0.0;  ///< wall time spent in add_frame() and finish()
};

class LoopClosure3D {
 public:
  /// Throws Error for an unknown registration method or options out of range.
  explicit LoopClosure3D(const LoopClosure3DOptions& options = {});

  /// Adds the next frame: its points in the sensor frame (deskewed, downsampled; may be empty)
  /// and its odometry pose (sensor in the odometry's world frame). The first frame and each one
  /// past the keyframe thresholds become keyframes and may close loops. Non-finite points are
  /// dropped; a non-finite pose is replaced by the previous one. Returns true for a keyframe.
  bool add_frame(const PointCloud& points, const Pose& odometry_pose);
  /// Optimizes once more (so the outlier flags are current); call after the last frame.
  void finish();

  std::size_t frames() const { return graph_.frames(); }
  /// The optimized pose of frame `index`: its keyframe's optimized pose followed by the odometry
  /// motion from that keyframe.
  Pose pose(std::size_t index) const;
  std::vector<Pose> poses() const;
  /// Every accepted loop edge, in order of addition.
  const std::vector<Loop3D>& loops() const { return graph_.loops(); }
  const LoopClosure3DCounts& counts() const { return counts_; }
  const PoseGraph3D& graph() const { return graph_.graph(); }
  /// Keyframe `k`'s submap (in its frame), as verification saw it.
  const PointCloud& submap(std::size_t keyframe) const { return keyframes_.at(keyframe).submap; }
  std::size_t keyframes() const { return keyframes_.size(); }
  /// Bytes the verification structures kept between keyframes hold (at most
  /// verification_memory_mb once add_frame() returns).
  std::size_t verification_memory_bytes() const;
  /// The keyframe frame `index` belongs to (the last keyframe at or before it), and the frame's
  /// odometry pose in that keyframe's frame: pose(index) == graph().pose(keyframe) * offset.
  std::size_t keyframe_of(std::size_t index) const { return graph_.keyframe_of(index); }
  const Pose& offset_in_keyframe(std::size_t index) const {
    return graph_.offset_in_keyframe(index);
  }

 private:
  struct Keyframe {
    std::size_t frame = 0;
    PointCloud submap;
    /// The submap with what verification built from it, while kept (verification_memory_mb).
    std::unique_ptr<PreparedCloud> prepared;
    Pose odometry = Pose::Identity();
    double path = 0.0;  ///< m of odometry travel since the first keyframe
  };
  struct RecentFrame {
    PointCloud points;  ///< downsampled to submap_voxel
    Pose odometry;
  };
  /// The recent frames in the keyframe's frame, downsampled to fit max_submap_points; adapts
  /// frame_voxel_.
  PointCloud build_submap(const Pose& keyframe_odometry);
  void close_loops(std::size_t keyframe);
  /// Keyframe k's prepared submap, built when not kept; now the most recently used.
  PreparedCloud& prepared(std::size_t keyframe);
  static constexpr std::size_t kNoKeyframe = static_cast<std::size_t>(-1);
  /// Drops the least recently used prepared submaps, except keyframe `keep`'s, until the rest fit
  /// verification_memory_mb.
  void trim_prepared(std::size_t keep);
  void optimize();
  /// The estimate gate (m) between a keyframe and an older candidate.
  double correction_allowed(std::size_t keyframe, std::size_t candidate) const;

  LoopClosure3DOptions options_;
  KeyframeGraph<3, Loop3D> graph_;
  PlaceDatabase3D places_;
  std::vector<Keyframe> keyframes_;
  std::deque<RecentFrame> recent_;
  std::list<std::size_t> prepared_order_;  ///< keyframes with a prepared submap, most recent first
  double frame_voxel_ = 0.0;  ///< m, the voxel new frames are kept at (submap_voxel or coarser)
  std::size_t last_loop_keyframe_ = 0;  ///< the last keyframe that added a loop edge
  LoopClosure3DCounts counts_;
};

}  // namespace scanmatch
