#pragma once
// Correlative scan matching over a window (Olson's idea, our own multi-level branch and bound): the
// reference becomes a smoothed likelihood grid; each rotation of the current scan is scored at
// every translation of the window. Max-filtered copies of the grid (blocks of 4, 16 and 64 cells
// a side) bound the score of a whole block of translations; the most promising blocks are split
// first, so most of the window is dismissed without looking at its cells.
// register_scans runs it first when Registration2DOptions::search_window is set.

#include <cmath>
#include <memory>
#include <optional>

#include "scanmatch/core/scan2d.hpp"

namespace scanmatch {

/// A reference's likelihood grid built once for several searches onto it (the odometry searches
/// each step over +-45 deg, +-90 deg and sometimes the whole turn, and looks at the step's spread):
/// building the grid was half of a step's time on long-range logs (freiburg-campus, acapulco).
/// Spans all of the reference's (filled) surfaces; `resolution` m, coarser where the area is huge.
/// Cheap to copy (shared, immutable).
class CorrelativeGrid {
 public:
  /// Throws Error unless `resolution` is positive. An empty reference gives an empty grid, onto
  /// which no search finds anything.
  CorrelativeGrid(const Scan2D& reference, double resolution, double fill_gap = 0.0);
  /// From surface points already filled (filled_surfaces): the newest reference's and, where
  /// `older` holds any (earlier references' surfaces in the newest one's frame), the mean of the
  /// two sets' likelihoods: returns that line up with the newest reference only where the sensor
  /// did not move (samples of walls at a grazing angle) do not line up with the older ones.
  CorrelativeGrid(const std::vector<Eigen::Vector2d>& newest,
                  const std::vector<Eigen::Vector2d>& older, double resolution);
  bool empty() const { return impl_ == nullptr; }
  double resolution() const {
    return requested_resolution_;
  }  ///< as asked (the grid may be coarser)

  struct Impl;  // the grid and its max-filtered levels (correlative_search.cpp)
  const Impl& impl() const { return *impl_; }

 private:
  std::shared_ptr<const Impl> impl_;
  double requested_resolution_ = 0.05;
};

/// The pose within +- `window` (m, in x and y) and +- `angle_window` (rad) of `initial` whose
/// transformed points best hit a smoothed likelihood grid of the reference, found exactly at the
/// grid's resolution (m; coarser when the area is huge). Throws Error unless the window and the
/// resolution are positive and the angle window is not negative; returns `initial` when no
/// reference point lies where the current scan can land.
/// With `fill_gap` (m, 0: off) the reference's surfaces are filled in first (filled_surfaces).
Pose2 correlative_search(const Scan2D& current, const Scan2D& reference, const Pose2& initial,
                         double window, double angle_window, double resolution = 0.05,
                         double fill_gap = 0.0);

struct CorrelativeMatch {
  Pose2 pose = Pose2::Identity();  ///< the best pose, or the initial guess when not `found`
  /// The best pose's score as a share of the best possible (every point of the thinned current
  /// scan on a reference surface): 0 to 1.
  double score = 0.0;
  bool found = false;  ///< false when no pose reaches `min_score`
};

/// correlative_search that also reports the score and gives up on poses scoring below `min_score`
/// (a share, 0 to 1): a search for a pose that must fit well (a loop closure's) prunes from the
/// start and ends early where nothing fits.
CorrelativeMatch correlative_match(const Scan2D& current, const Scan2D& reference,
                                   const Pose2& initial, double window, double angle_window,
                                   double resolution = 0.05, double fill_gap = 0.0,
                                   double min_score = 0.0);

/// correlative_match onto a prepared grid (its resolution and fill as it was built with).
CorrelativeMatch correlative_match(const Scan2D& current, const CorrelativeGrid& reference,
                                   const Pose2& initial, double window, double angle_window,
                                   double min_score = 0.0);
/// The same over a rectangular window: +- window.x() and +- window.y() (m) along the
/// reference's axes (the odometry's long search reaches far ahead, not sideways).
CorrelativeMatch correlative_match(const Scan2D& current, const CorrelativeGrid& reference,
                                   const Pose2& initial, const Eigen::Vector2d& window,
                                   double angle_window, double min_score = 0.0);

/// Several correlative_match searches of one scan about one guess onto one grid, each window
/// holding the ones before (the odometry's narrow, wide, whole-turn and long searches): the scan is
/// prepared once, and a search looks again at no earlier window that lies inside its own (it
/// starts from the best found there). Each search returns what correlative_match would.
class CorrelativeSearches {
 public:
  CorrelativeSearches(const Scan2D& current, const CorrelativeGrid& reference,
                      const Pose2& initial);
  ~CorrelativeSearches();
  CorrelativeSearches(const CorrelativeSearches&) = delete;
  CorrelativeSearches& operator=(const CorrelativeSearches&) = delete;
  /// correlative_match over +- window.x() and +- window.y() (m) and +- `angle_window` (rad).
  CorrelativeMatch match(const Eigen::Vector2d& window, double angle_window,
                         double min_score = 0.0);

 private:
  struct State;
  std::unique_ptr<State> state_;
};

/// How much a scan's translation is left open at a pose (`at`, current in the reference's frame):
/// the translations within +- `window` (m) of it, each at its best rotation within
/// +- `angle_window` (rad), that score within `margin` (a share) of the window's best.
struct CorrelativeSpread {
  /// Of those translations' offsets from `at` (m^2): where they lie along a corridor whose walls
  /// fit anywhere, it is long that way; a pose in a wrong basin shows the better one as an offset.
  Eigen::Matrix2d second_moment = Eigen::Matrix2d::Zero();
  double best_score = 0.0;  ///< the window's best, as a share of the best possible
  std::size_t poses = 0;    ///< translations counted (0: nothing could be scored)
  /// With `toward`: the counted translation nearest to it, at its best rotation (the cells'
  /// resolution); else, or when nothing counted, `at`.
  Pose2 nearest = Pose2::Identity();
};

/// How an odometry step's spread is looked at, by Mapper2D (open steps) and LoopClosure2D (its
/// odometry edges): each translation at its best rotation within +- this (rad), on cells this
/// coarse (m), as the spread costs the more the flatter the fit.
inline constexpr double kStepSpreadAngle = 2.0 * M_PI / 180;
inline constexpr double kStepSpreadResolution = 0.1;

/// Every translation that can come within the margin is scored exactly (blocks of them bounded as
/// the search bounds them, best first), so a flat fit costs far more than a sharp one: keep the
/// window small and the resolution coarse (0.1 m).
/// Throws Error unless the window and resolution are positive and the margin is not negative.
CorrelativeSpread correlative_spread(const Scan2D& current, const Scan2D& reference,
                                     const Pose2& at, double window, double angle_window,
                                     double resolution, double fill_gap, double margin,
                                     const std::optional<Eigen::Vector2d>& toward = std::nullopt);
/// correlative_spread onto a prepared grid.
CorrelativeSpread correlative_spread(const Scan2D& current, const CorrelativeGrid& reference,
                                     const Pose2& at, double window, double angle_window,
                                     double margin,
                                     const std::optional<Eigen::Vector2d>& toward = std::nullopt);

/// The direction the counted translations spread most along (unit; any when none counted) and
/// their RMS spread along it, m: a step whose spread reaches a few decimetres is open that way.
struct SpreadAxis {
  Eigen::Vector2d direction = Eigen::Vector2d::UnitX();
  double rms = 0.0;
};
SpreadAxis widest_spread(const CorrelativeSpread& spread);

/// The scan's points plus points every `step` (m) between beam neighbours up to `max_gap` apart
/// that lie on one straight surface (a third neighbour on their line). Two scans sample a wall
/// seen at a grazing angle at different places, metres apart; scored against the samples alone, a
/// scan fits best where its samples fall on the reference's, which along a corridor is where the
/// sensor did not move (steps came out short on ACES and Intel: docs/planar.md).
std::vector<Eigen::Vector2d> filled_surfaces(const Scan2D& scan, double max_gap, double step);

}  // namespace scanmatch
