#pragma once
// 2D scan-to-scan mapping (docs/methods.md section 2 step 6): each scan is registered onto the
// previous one (or the last keyframe) from a motion prior and the results are chained into global
// poses.

#include <cstddef>
#include <deque>
#include <string>
#include <utility>
#include <vector>

#include "scanmatch/core/scan2d.hpp"
#include "scanmatch/mapping2d/scan2d_stats.hpp"
#include "scanmatch/registration/planar/correlative_search.hpp"
#include "scanmatch/registration/planar/registration2d.hpp"

namespace scanmatch {

class Reference2D;  // registration/planar/reference2d.hpp

struct Mapper2DConfig {
  /// The step's registration, with the correlative search on (+- 1.3 m; register2d's is off):
  /// scans of the classic logs are up to 1.5 m and 78 deg apart.
  Registration2DOptions registration{.search_window = 1.3};
  /// Initial guess of each step: the previous step's motion (constant velocity) or none (the
  /// identity). The paper chains with the previous result.
  bool constant_velocity = true;
  double min_range = 0.05;  ///< m: nearer returns are dropped
  /// A result that moves farther than this from the initial guess is a failed match, not a
  /// motion: the scan is bridged by the guess, so that one failure does not become the next
  /// scan's constant-velocity guess. Widened to the correlative search's window (+0.5 m, +0.2
  /// rad) where it runs: a turn the search was asked to find is not a failure.
  double max_correction = 2.0;                      ///< m
  double max_correction_angle = 60.0 * M_PI / 180;  ///< rad
  /// Scans are matched against the last keyframe, which is replaced once the sensor has moved
  /// this far from it: errors then add up per keyframe, not per scan. 0 and 0: every scan is a
  /// keyframe (the paper's scan-to-scan chaining).
  double keyframe_distance = 0.0;  ///< m
  double keyframe_angle = 0.0;     ///< rad
  /// Scans with point times (Scan2D::times) are deskewed to their first beam by the previous
  /// step's motion, as a constant velocity (a Neato turning at 120 deg/s turns 24 deg within one
  /// 5 Hz scan). Off by default: on room-2d it gains little (10-step rotation error 2.54 -> 2.31
  /// deg for pl-icp over 300 scans) where deskewing by the true motion gives 0.35 deg; the
  /// estimated velocity is the weak part (docs/planar.md).
  bool deskew = false;
  /// With the correlative search on, it runs a second time over +- this angle (rad) and that
  /// result wins when clearly more of the scan's points (5 % of them) then lie within 15 cm of the
  /// reference's surfaces: logs at 1 Hz turn a corner of up to 80 degrees between two scans
  /// (ACES), and in rectilinear buildings the narrow search then settles 90 degrees off, where the
  /// walls line up again but the rest does not. The wide search alone finds more false matches.
  /// It costs about as much as the first search (intel 2.6 -> 6.8 ms per scan). 0: off.
  double wide_search_angle = 90.0 * M_PI / 180;
  /// Only when fewer than this share of the points fit after the first search (1: always; lower
  /// values save time but miss 90-degree errors, whose walls fit).
  double wide_search_below = 1.0;
  /// With the correlative search on, where even the best of those leaves fewer than this share of
  /// the points fitting, the step is weak (Scan2DStats::weak_fit) and the search runs once more
  /// over the whole turn (+- 180 degrees), winning by the same 5 %: at 1 Hz a robot
  /// turns a corner of 90 degrees between two scans, and after such a turn the constant-velocity
  /// guess expects another, so the truth lies beyond +- 90 degrees of the guess (corridor-2d
  /// over 800 scans). On the Radish logs such steps are 1-9 % of the scans and the whole turn
  /// changes none of them. 0: off.
  double full_turn_search_below = 0.6;
  /// Where the scans leave a step open (a corridor whose walls fit all along it, a junction that
  /// fits two ways), they cannot choose and the registration settles wherever its own bias takes
  /// it: on ACES (1 Hz) steps along corridors came out 0.1 or 2.3 m where the robot drove 1.1 m.
  /// Within `open_step_window` (m) of the registered pose, the translations that fit within
  /// `open_step_margin` (a share of the points) of the best one (correlative_spread) are all the
  /// scans' answer; when they spread at least `open_step_spread` (m, RMS) the one nearest the
  /// motion prior is taken along the open direction (registered again from there, for the
  /// rotation and the part across it; last_stats().open_step_from_prior). Only
  /// when that one lies within `open_step_prior_distance` (m) of the prior: farther, the scans
  /// contradict the prior (the robot turned a corner or stopped) and the registration stands.
  /// Needs `constant_velocity`. 0 (window): off.
  double open_step_window = 1.5;
  double open_step_margin = 0.05;
  double open_step_spread = 0.3;
  double open_step_prior_distance = 0.5;
  /// Where that prior is contradicted but the scans fit (at least full_turn_search_below of the
  /// points: only the step's length is open), the step's prior is instead straight on along the
  /// registered heading at the median length of the last `open_step_speed_steps` steps: after a
  /// corner turned in one step the constant-velocity prior turns on and points sideways, while
  /// the robot drives on at its speed (corridor-2d scans 82-85 slid to 0.4 m of 0.9). 0: off.
  int open_step_speed_steps = 5;
  /// With the correlative search on, a search over +- this translation ahead and behind (m, about
  /// the motion prior along the previous scan's heading; sideways as far as the first search, over
  /// the wide search's angle) where the searches above leave the step weak (fewer than
  /// `long_search_below` of the points fit) or open (open_step_spread): the robot moved farther
  /// than the prior says. It wins by the same 5 % of the points. A log that keeps a scan every 1
  /// to 3 m (orebro) steps 2-3 m where the previous step was 1 m, or where the previous step slid
  /// short along a corridor; within +-1.3 m of that prior only a wrong pose fits. 0: off.
  double long_search_window = 3.5;
  double long_search_below = 0.7;
  /// With the correlative search on, a scan of which fewer than this share of the points fit
  /// its reference is not made the next scan's reference: it shows little of the scene the
  /// scans about it see (a laser pitched onto the ground, people beside it, open space), its
  /// step is the motion prior's guess, and scan to scan every later pose would inherit that
  /// guess's error (freiburg-campus's robot weaves 10-12 deg a scan one way and back, and such
  /// steps took the prior's turn the wrong way). The next scan registers onto the older
  /// reference; at most `max_unfit_references_skipped` scans in a row, as the scene moves on.
  /// 0: off.
  double reference_fit_below = 0.2;
  int max_unfit_references_skipped = 3;
  /// While the robot moves steadily (its last `unfit_steady_steps` steps each within
  /// unfit_max_correction and unfit_max_correction_angle of the last one), such a scan's step may
  /// depart from the constant-velocity prior by no more than that either; farther, the scan is
  /// bridged by the prior (last_stats().steady_prior). What little fits says little about the
  /// motion, and a registration on it lands where a few returns happen to line up: on
  /// freiburg-campus, scans 490-497 (fits 0.05-0.18, the laser seeing little but ground and
  /// scattered trunks) came out 0.9-2.6 m and up to 37 deg from the prior, backwards twice,
  /// where the robot drove on at its steady 1.1 m a scan. An unsteady prior (weaving on the
  /// spot, starting off: 1020-1029) is no better than such a registration and bounds nothing.
  /// 0 (distance or angle): that bound off.
  double unfit_max_correction = 0.3;
  double unfit_max_correction_angle = 10.0 * M_PI / 180;
  int unfit_steady_steps = 5;
  /// With the correlative search on, the searches score each scan against its reference and,
  /// as an equal second part, the `submap_scans` - 1 references before it (scan to submap):
  /// returns that line up with the last scan only where the robot stood still (wall samples at a
  /// grazing angle, things near the path) do not line up with the scans before. ACES scans
  /// 316-320, a corridor walked at 1.1 m a scan, came out 0-0.2 m scan to scan once its
  /// no-return readings were no longer points. The older references are let go where a step
  /// joining them left fewer than `submap_link_fit` of its points fitting (or was bridged): its
  /// error would double the walls. 1: scan to scan.
  int submap_scans = 3;
  double submap_link_fit = 0.8;
};

class Mapper2D {
 public:
  /// Throws Error for an unknown method.
  explicit Mapper2D(const Mapper2DConfig& config);
  /// Registers the next scan, taken at `timestamp` (s; used with its point times to deskew);
  /// returns the laser's pose at the scan's first beam in the frame of the first scan. A scan too
  /// small to register is bridged by the motion prior (last_stats().bridged), never fatal.
  Pose2 add_scan(const Scan2D& scan, double timestamp = 0.0);
  /// The last scan as registered (deskewed where it was): what a map should be built from.
  const Scan2D& last_scan() const { return last_scan_; }
  const Scan2DStats& last_stats() const { return stats_; }
  const Pose2& pose() const { return pose_; }
  std::size_t scans() const { return scans_; }

 private:
  /// `whole_turn`: the correlative search looked over every rotation, so any turn is plausible;
  /// `window`: the translation window (m) the winning search looked over.
  bool plausible_correction(const Pose2& correction, bool whole_turn, double window) const;
  /// The last unfit_steady_steps motions each lie near the newest (departs_from_prior).
  bool steady_motion() const;
  /// `correction` (from the prior) exceeds unfit_max_correction or unfit_max_correction_angle.
  bool departs_from_prior(const Pose2& correction) const;
  /// `registered` moved along the direction the scans leave open (`spread` about it, if they do)
  /// to the fitting translation nearest the motion prior `guess` (open_step_window).
  Pose2 prior_along_open_direction(const Scan2D& current, const Reference2D& reference,
                                   const CorrelativeSpread& spread, const Pose2& registered,
                                   const Pose2& guess);

  Mapper2DConfig config_;
  Scan2D keyframe_, last_scan_;
  /// The references before keyframe_ still in the search (submap_scans), newest first: their
  /// filled surfaces (filled_surfaces, in their own frames) and their poses.
  std::deque<std::pair<std::vector<Eigen::Vector2d>, Pose2>> older_references_;
  /// The last steps' motions, newest last: as many as open_step_speed_steps (their lengths) and
  /// unfit_steady_steps (steady_motion) need.
  std::deque<Pose2> recent_motions_;
  double last_timestamp_ = 0.0, motion_interval_ = 0.0;  ///< s; motion_ took motion_interval_
  Pose2 keyframe_pose_ = Pose2::Identity();
  Pose2 pose_ = Pose2::Identity(), motion_ = Pose2::Identity();
  std::size_t scans_ = 0;
  int unfit_references_skipped_ = 0;  ///< scans in a row not made the reference
  Scan2DStats stats_;
};

}  // namespace scanmatch
