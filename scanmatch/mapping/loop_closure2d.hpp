#pragma once
// 2D loop closure on top of scan-to-scan odometry: keyframes become nodes of a pose graph
// (pose_graph.hpp) chained by odometry edges; each new keyframe looks for earlier keyframes of the
// same place, verifies every candidate geometrically and adds the verified ones as loop edges,
// then the graph is optimized.
//
// Candidates come from two sources (their union, loop_candidates.hpp): earlier keyframes near the
// new one in the current (optimized) estimate, and the place database (place_database.hpp), both
// skipping the newest `skip_recent` keyframes. 2D descriptors tell similar rooms apart
// poorly, so verification (loop_verification2d.hpp) does the real work, and a verified loop must
// also agree with the estimate. The graph's robust kernel and chi-square test (PoseGraphConfig)
// catch what still slips through. This file holds the orchestration: keyframes, odometry edges,
// when to search and when to optimize.

#include <cstddef>
#include <memory>
#include <utility>
#include <vector>

#include "scanmatch/core/scan2d.hpp"
#include "scanmatch/features/place_database.hpp"
#include "scanmatch/mapping/keyframe_graph.hpp"
#include "scanmatch/mapping/loop_candidates.hpp"
#include "scanmatch/mapping/loop_verification2d.hpp"
#include "scanmatch/mapping/pose_graph.hpp"

namespace scanmatch {

struct LoopClosure2DOptions {
  /// A new keyframe once the odometry has moved this far from the last one (m or rad). Every
  /// keyframe is verified against its candidates, loop closure's main cost: 1 m against 0.5 m
  /// verified 20 % fewer candidates on intel with a map as good or better on the three CARMEN logs
  /// (docs/planar.md).
  double keyframe_distance = 1.0;
  double keyframe_angle = 20.0 * M_PI / 180;
  /// Odometry edges between consecutive keyframes get a fixed diagonal information from these
  /// standard deviations (m for x and y, rad for theta): scan matching over 0.5 m drifts by a few
  /// cm and a fraction of a degree.
  double odometry_sigma_xy = 0.05;
  double odometry_sigma_theta = 0.5 * M_PI / 180;
  /// Where the scans leave a step open, its edge holds it loosely: the translations within this
  /// window (m) of the step, each at its best rotation, that fit the previous keyframe's scan
  /// within `odometry_spread_margin` (a share of the points) of the best (correlative_spread);
  /// their spread about the step beyond `odometry_spread_normal` (m) widens the edge's
  /// translation covariance in its direction. A corridor's walls fit all along it, and on ACES
  /// every step that slid or kept a turn's wrong translation spread 0.36 m or more, 95 % of the
  /// right ones below 0.13 m; with a fixed sigma a loop cannot stretch such a step back and the
  /// graph bends every other step instead. 0: the fixed sigmas alone.
  double odometry_spread_window = 1.5;
  double odometry_spread_margin = 0.05;
  double odometry_spread_normal = 0.1;
  /// A scan whose step from the last keyframe is open, its spread at least `open_step_spread` (m),
  /// becomes a keyframe however little the odometry moved (a slid step is short): only a node of
  /// its own lets the graph stretch it. ACES's wrong steps spread 0.36 m and more; room-2d's
  /// hallway, doors every 5 m, spreads right steps up to 0.3 m. A laser at tens of Hz down a plain
  /// corridor would make nearly every scan a keyframe this way: turn it off for such data.
  bool open_steps_are_keyframes = true;
  double open_step_spread = 0.3;
  /// A turn on the spot among people or clutter can leave the rotation open: another rotation
  /// 10-90 degrees off fits the previous keyframe's scan nearly as well (rotation_ambiguity_2d).
  /// A keyframe step whose far rotations reach `rotation_open_ratio` of its own fit gets a loose
  /// rotation (`rotation_open_sigma_theta`), and the estimate check lets a loop across it turn the
  /// newer keyframes about it (max_correction). fhw's spin among visitors reaches 0.90 and 1.12
  /// at scans 57 and 60, around the step that is 80 degrees wrong; ACES's and corridor-2d's steps
  /// stay below 0.81, and intel's 2 open turning steps are held by loops (its map is unchanged).
  /// 0: off.
  double rotation_open_ratio = 0.9;
  double rotation_open_sigma_theta = 30.0 * M_PI / 180;
  /// Only steps that turn at least this much (rad) are tested, and steps whose registration fitted
  /// poorly (add_scan's weak_fit): a turn is what leaves the scans little in common, and the test
  /// costs loop closure ~15 % of its time if every keyframe step takes it (intel). A 1 Hz robot
  /// that turns a 90-degree corner between two scans can leave two rotations fitting alike, and
  /// the odometry may take the one that does not turn (corridor-2d over 800 scans).
  double rotation_open_min_turn = 10.0 * M_PI / 180;
  /// A keyframe step holding a scan the odometry could not register (it fit its reference at
  /// less than Mapper2DConfig::reference_fit_below, or was bridged) keeps this share of its
  /// edge's information (its standard deviations doubled at 0.25): its motion is the prior's
  /// guess or a registration on little, and a graph that holds it as firmly as a measured step
  /// bends every other step of a loop instead. freiburg-campus has 26 such scans among 2008, the
  /// other logs and both simulations none: 1.97 -> 0.62 m loop-closed there (the scans bridged by
  /// the steady prior, unfit_max_correction, included); any share from 0.15 to 0.8 gave 0.52-0.68
  /// m. 1: as firm as the rest.
  double unfit_step_information = 0.25;
  /// Loop edges likewise: a verified registration is good to a few cm.
  double loop_sigma_xy = 0.05;
  double loop_sigma_theta = 0.5 * M_PI / 180;
  /// The newest keyframes are never candidates: the previous one is the odometry edge's. Keyframes
  /// just older are: a turn on the spot comes back to the walls it started from, and an edge
  /// there stops its steps' rotation errors adding up (ACES's dead end at scans 217-233 turned
  /// 6 deg too far over 15 steps; loop-closed ATE 0.26 m with 30 skipped, 0.12 with 2).
  std::size_t skip_recent = 2;
  /// The candidate keyframe's neighbours within this many keyframes either side (older than the
  /// skipped recent ones) join its scan as the verification's reference (verify_loop_2d's
  /// candidate_neighbours). 0: scan against scan.
  std::size_t submap_keyframes = 6;
  /// A loop's pairing error may reach this many times the run's own floor, where that exceeds
  /// verification.max_error: the error of each keyframe paired onto the previous one at the
  /// odometry's step, its lower quartile over the keyframes so far (from 20 on). Outdoors and in
  /// large halls (long ranges, vegetation, clutter) true loops pair at 0.045-0.056 m: the fixed
  /// 0.04 m rejected freiburg-campus's revisits of scans 200-350 (scores 0.8-0.9, 0.94 of the
  /// points paired), and that section stayed 4-7 m off. The quartile: intel 0.014 m, room-2d
  /// 0.015, ACES 0.023, fhw 0.026, freiburg-campus 0.027, acapulco 0.037. 0: the fixed bound.
  double max_error_per_floor = 1.8;
  /// Loop edges hold what the match determines (its Hessian's shape at loop_sigma_xy), not the
  /// same certainty in every direction: a loop along a plain corridor holds nothing along it.
  bool hessian_loop_information = true;
  /// A sliding loop (LoopVerification2D::sliding) keeps this share of its information along its
  /// open direction. Its re-fit there starts from the estimate and moves little, so what it holds
  /// is mostly where the estimate put the two visits when the loop was made. With nothing held
  /// along a corridor (whose open odometry steps are loose as well) the graph stretched the
  /// loosest steps there when other loops pulled: corridor-2d over 800 scans 0.58 m with nothing
  /// kept, 0.30 m with 0.3 (0.29 with 0.03); ACES 0.101 -> 0.098 m, room-2d seeds 1-5 on average
  /// 0.45 -> 0.40 m. 0: nothing (the loop holds the heading and the translation across only).
  double sliding_information_kept = 0.3;
  /// Candidates (loop_candidates.hpp): earlier keyframes within 4 m in the current estimate, the 2
  /// nearest of different visits (with the default skip_recent, 2 keyframes apart at least), and
  /// the place database's best match below descriptor distance 0.2.
  LoopCandidateOptions candidates{.proximity_radius = 4.0,
                                  .max_proximity_candidates = 2,
                                  .max_descriptor_distance = 0.2,
                                  .max_descriptor_candidates = 1};
  /// Repeated structure (identical rooms, doors at equal spacing) verifies perfectly at the wrong
  /// place, so a verified loop must also agree with the current estimate: its translation may
  /// differ from the estimate's relative pose by at most this base (m) plus this share of the
  /// odometry path between the two keyframes (how far the estimate can have drifted).
  /// Across a rotation-open odometry step (rotation_open_ratio) the estimate's heading is not
  /// held: the loop must agree with the estimate once the keyframes after that step are turned
  /// about it to the loop's heading.
  double max_correction = 1.0;
  double max_correction_per_m = 0.05;
  /// How far (m) verification can move a place-database match from its start (no translation):
  /// a match farther than the gate above plus this from the new keyframe in the estimate is
  /// ruled out without being verified (verified, the gate would reject it but for a slide), unless
  /// a rotation-open step between the two keyframes lets the gate turn the newer ones. The search
  /// window's corner is 2.8 m away, but a sliding match is fitted again at the estimate's
  /// position along its corridor: on ACES such loops came from matches up to 6.6 m beyond the
  /// gate. With 7 m every loop on the six CARMEN logs and room-2d stays as it was, and 9-25 % of
  /// their candidates are ruled out (intel 177 of 2002, ACES 211 of 846). Negative: every match
  /// is verified.
  double registration_reach = 7.0;
  /// The odometry's doubt between two keyframes widens the search between them: each weak step
  /// between them (a scan few points of which fit: Mapper2D's weak_fit) scales the proximity
  /// radius and the verification's search window by this much more, up to max_doubt_widening
  /// times. freiburg-campus's revisits after 140-250 weak steps lay 3-11 m apart in the estimate,
  /// beyond 4 m; a ring of plain corridors, whose odometry fits (corridor-2d: at most 2 weak
  /// steps), keeps the narrow search, where a wide one finds aliases. 0: off.
  double widening_per_weak_step = 0.01;
  double max_doubt_widening = 2.5;
  /// Loop edges are looked for at every this-many keyframes (1: each one) ...
  std::size_t search_every = 1;
  /// ... and not at the next this-many keyframes after one that added a loop edge: on a second
  /// pass every keyframe revisits a place, and a loop every few metres holds the graph as well
  /// as one per keyframe at a fraction of the verification cost, loop closure's main cost
  /// (LoopClosure3DOptions likewise). 0: no pause.
  std::size_t keyframes_between_loops = 0;
  /// The graph is optimized when a new loop edge would move the keyframe's points 5 m away by
  /// more than this (m) from the current estimate; loops that agree with it wait for the next
  /// optimization (finish() always runs one). On intel 0.1 ran a quarter of the optimizations
  /// (79 of 329) with the same map, 0.4 fewer still with the same map. 0: after every loop edge.
  double optimize_above = 0.4;
  /// When an optimization moves the new keyframe by more than this (m at 5 m, as optimize_above),
  /// the `recheck_keyframes` keyframes before it look for loops again from where it put them:
  /// they looked while misplaced by as much, often beyond the verification's search window
  /// (ACES's dead end came back to its mouth 4 m off; only the descriptor's candidates a few scans
  /// later joined it to the start, and the steps between stayed unheld). 0 keyframes: never.
  double recheck_above = 1.0;
  std::size_t recheck_keyframes = 10;
  LoopVerification2DOptions verification;
  PlaceDescriptor2DOptions descriptor;
  PoseGraphConfig graph;
};

/// An accepted loop edge.
struct Loop2D {
  std::size_t from_keyframe = 0, to_keyframe = 0;  ///< to is the newer keyframe
  std::size_t from_scan = 0, to_scan = 0;          ///< their indices among all added scans
  Pose2 relative = Pose2::Identity();              ///< to in the frame of from
  double paired_fraction = 0.0, error = 0.0;
  /// Holds the heading and the translation across `slide_direction` (in the newer keyframe's
  /// frame), and along it only LoopClosure2DOptions::sliding_information_kept of the match's
  /// information; `relative` is then the re-fit started from the estimate's position along it.
  bool sliding = false;
  Eigen::Vector2d slide_direction = Eigen::Vector2d::Zero();
  bool outlier = false;  ///< judged an outlier by the graph's last optimize()
};

struct LoopClosure2DCounts {
  std::size_t keyframes = 0;
  std::size_t candidates = 0;  ///< candidate pairs proposed (after merging both sources)
  std::size_t verified = 0;    ///< candidates that passed the geometric check (loop edges added)
  std::size_t sliding = 0;     ///< of those, accepted as sliding (LoopVerification2D::sliding)
  std::size_t rejected_by_verification = 0;
  /// Verified but too far from the current estimate (max_correction): not added.
  std::size_t rejected_by_estimate = 0;
  /// Place-database matches ruled out before verification (registration_reach); not candidates.
  std::size_t ruled_out_by_estimate = 0;
  std::size_t outliers = 0;  ///< loop edges the graph judged outliers at its last optimize()
  std::size_t optimizations = 0;
  /// Odometry edges whose step the scans leave open (a spread of at least open_step_spread).
  std::size_t open_odometry_edges = 0;
  /// Odometry edges whose rotation the scans leave open (rotation_open_ratio).
  std::size_t rotation_open_odometry_edges = 0;
  /// Of the verified loops, those the estimate check let through only by turning the keyframes
  /// after a rotation-open step.
  std::size_t turned_at_open_rotation = 0;
  /// The pairing error a loop could have at most when the last keyframe looked for loops
  /// (verification.max_error, raised by max_error_per_floor), m.
  double max_error_m = 0.0;
  /// Wall time spent in add_scan() (or add_step() and making its steps) and finish().
  double total_ms = 0.0;
};

/// How well the best rotation 10-90 degrees off the step `measurement` (current in the previous
/// scan's frame) fits, against the step's own rotation: the correlative scores (translations
/// within +- `window` m) of the far rotations' best over the best within 4 degrees of the step.
/// Near 1 or above, the scans do not tell the rotation; a step along walls scores far below.
/// 0 when nothing could be scored. With `at_least` the far rotations are searched only for fits
/// reaching that share of the step's own: the ratio is exact where it is at least `at_least`,
/// and below it otherwise (the search then ends early, as a caller that compares with a threshold
/// needs no more: loop closure's test ran 3x faster on intel).
double rotation_ambiguity_2d(const Scan2D& current, const Scan2D& previous,
                             const Pose2& measurement, double window = 0.5, double at_least = 0.0);

/// Throws Error naming the problem for an unknown registration method or options out of range.
void check_loop_closure_2d_options(const LoopClosure2DOptions& options);

/// What loop closure makes of one scan from the odometry alone, before the graph: whether the scan
/// becomes a keyframe and, for a keyframe after the first, its odometry edge and pairing floor.
struct KeyframeStep2D {
  Pose2 odometry = Pose2::Identity();  ///< the scan's odometry pose (non-finite: the last one)
  Pose2 offset = Pose2::Identity();    ///< in the frame of its keyframe (itself, if one)
  bool keyframe = false;
  // A keyframe after the first:
  Pose2 measurement = Pose2::Identity();                  ///< from the previous keyframe
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();  ///< of its odometry edge
  bool open = false;            ///< the scans leave the step open (open_step_spread)
  bool rotation_open = false;   ///< the scans leave its rotation open (rotation_open_ratio)
  double pairing_error = -1.0;  ///< pairing_error_2d onto the previous keyframe (negative: none)
  // A keyframe:
  std::size_t weak_steps = 0;  ///< weak-fit scans since the first scan
  PlaceDescriptor2D descriptor;
  double ms = 0.0;  ///< the time it took
};

/// The odometry's side of LoopClosure2D: keyframes and their odometry edges depend on the
/// odometry's poses and scans alone, so a run can make them on the odometry's thread when loop
/// closure's falls behind (intel) and hand them over with the scans (LoopClosure2D::add_step).
class LoopKeyframes2D {
 public:
  /// Throws Error for options out of range (check_loop_closure_2d_options).
  explicit LoopKeyframes2D(const LoopClosure2DOptions& options = {});
  /// The next scan, as LoopClosure2D::add_scan takes it.
  /// `unfit`: the scan fit its reference too poorly to be one, or was bridged
  /// (unfit_step_information).
  KeyframeStep2D add_scan(const Scan2D& scan, const Pose2& odometry_pose, bool weak_fit = false,
                          bool unfit = false);

 private:
  struct OdometryInformation {
    Eigen::Matrix3d information;
    bool open = false;
    bool rotation_open = false;
  };
  /// The information of an odometry edge from `previous` to `current`, which the odometry put at
  /// `measurement` (current in previous's frame).
  OdometryInformation odometry_information(const Scan2D& previous, const Scan2D& current,
                                           const Pose2& measurement) const;
  /// Marks a keyframe step rotation-open (rotation_open_ratio, for steps that turn at least
  /// rotation_open_min_turn or hold a weak fit) and loosens its edge's rotation to
  /// rotation_open_sigma_theta.
  void loosen_open_rotation(OdometryInformation& information, const Scan2D& previous,
                            const Scan2D& current, const Pose2& measurement, bool weak_fit) const;

  LoopClosure2DOptions options_;
  bool have_keyframe_ = false;
  Scan2D keyframe_points_;  ///< the last keyframe's scan
  Pose2 keyframe_odometry_ = Pose2::Identity();
  Pose2 last_offset_ = Pose2::Identity();  ///< the last scan's, in its keyframe's frame
  /// A scan since the last keyframe was registered with a weak fit (add_scan's weak_fit).
  bool weak_fit_since_keyframe_ = false;
  bool unfit_since_keyframe_ = false;  ///< likewise, add_scan's unfit
  std::size_t weak_steps_ = 0;         ///< weak-fit scans so far
};

class LoopClosure2D {
 public:
  /// Throws Error for an unknown registration method or options out of range.
  explicit LoopClosure2D(const LoopClosure2DOptions& options = {});

  /// Adds the next scan with its odometry pose (the laser's pose in the odometry frame). The
  /// first scan and each one past the keyframe thresholds become keyframes and may close loops.
  /// `weak_fit`: the odometry's registration of this scan fitted poorly (Scan2DStats::weak_fit),
  /// so the keyframe step that holds it takes the rotation test however little it turned.
  /// Returns true when the scan became a keyframe.
  /// `unfit`: the odometry could not register it (LoopKeyframes2D::add_scan).
  bool add_scan(const Scan2D& scan, const Pose2& odometry_pose, bool weak_fit = false,
                bool unfit = false);
  /// add_scan with the scan's step made elsewhere: by a LoopKeyframes2D of the same options fed
  /// every scan in order (the same results). Use one way or the other for a whole run. Throws
  /// Error when the first step is not a keyframe.
  bool add_step(const Scan2D& scan, const KeyframeStep2D& step);
  /// Optimizes once more (so the outlier flags are current); call after the last scan.
  void finish();

  std::size_t scans() const { return graph_.frames(); }
  /// The optimized pose of scan `index`: its keyframe's optimized pose followed by the odometry
  /// motion from that keyframe.
  Pose2 pose(std::size_t index) const;
  std::vector<Pose2> poses() const;
  /// Every accepted loop edge, in order of addition.
  const std::vector<Loop2D>& loops() const { return graph_.loops(); }
  const LoopClosure2DCounts& counts() const { return counts_; }
  const PoseGraph2D& graph() const { return graph_.graph(); }

 private:
  struct Keyframe {
    std::size_t scan = 0;
    Scan2D points;
    Pose2 odometry = Pose2::Identity();
    double path = 0.0;           ///< m of odometry travel since the first keyframe
    std::size_t weak_steps = 0;  ///< weak-fit scans since the first scan
    bool rotation_open = false;  ///< the odometry edge from the previous keyframe is so
    /// pairing_error_2d onto the previous keyframe at the odometry's step (negative: none).
    double pairing_error = -1.0;
  };
  /// How much wider the search between keyframe `newer` and an older one is
  /// (widening_per_weak_step).
  double doubt_widening(std::size_t older, std::size_t newer) const;
  /// The verification's max_error for loops found now (max_error_per_floor).
  double loop_max_error() const;
  /// Searches loops for the new keyframe, optimizes when they disagree with the estimate, and
  /// searches again for the keyframes before it when that moved the estimate far.
  void close_loops(std::size_t keyframe);
  /// Verifies `keyframe`'s candidates and adds the accepted loop edges (skipping pairs already
  /// joined); true when one disagrees enough with the estimate to call for an optimization.
  bool search_loops(std::size_t keyframe);
  /// Whether a loop putting keyframe `newer` at `implied` agrees with the estimate within
  /// `allowed` (m) once the keyframes after one rotation-open step between `older` and `newer`
  /// are turned about it to the loop's heading.
  bool agrees_turned_at_open_rotation(std::size_t older, std::size_t newer, const Pose2& implied,
                                      double allowed) const;
  /// The estimate gate (m) between keyframe `newer` and an older one (max_correction).
  double correction_allowed(std::size_t older, std::size_t newer) const;
  void optimize();
  /// Keyframe `keyframe` joined by the keyframes `joined` at their current relative poses,
  /// prepared for verification (kept for the next candidates: a keyframe is often the candidate
  /// of several new keyframes while the estimate stays). Shared: it outlives its eviction from
  /// the cache while verifications still use it.
  std::shared_ptr<const LoopReference2D> prepared_reference(std::size_t keyframe,
                                                            const std::vector<std::size_t>& joined);
  struct PreparedReference {
    std::size_t keyframe = 0;
    std::vector<std::pair<std::size_t, Pose2>> joined;  ///< each keyframe in `keyframe`'s frame
    std::shared_ptr<const LoopReference2D> reference;
  };
  /// The prepared references kept (bounded memory), the most recently used last.
  static constexpr std::size_t kPreparedReferences = 16;
  std::vector<PreparedReference> prepared_;

  LoopClosure2DOptions options_;
  KeyframeGraph<2, Loop2D> graph_;
  LoopKeyframes2D keyframer_;  ///< add_scan's
  PlaceDatabase2D places_;
  std::vector<Keyframe> keyframes_;
  LoopClosure2DCounts counts_;
  std::size_t last_loop_keyframe_ = 0;  ///< the newest keyframe that added a loop edge
};

}  // namespace scanmatch
