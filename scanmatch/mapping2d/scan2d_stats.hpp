#pragma once
// A scan's timing and diagnostics in the 2D mapper (Mapper2D::last_stats()) and the one
// description of them, a record (core/record.hpp): map2d's timing.csv columns, rows and reader
// (io/record_csv.hpp) and Python's Mapper2D.stats dictionaries come from describe(). A new
// statistic is a member of Scan2DStats and one line in describe().

#include <concepts>
#include <cstddef>
#include <type_traits>

namespace scanmatch {

/// One scan of the 2D mapper; the meaning of each field is its help text in describe().
struct Scan2DStats {
  double ms = 0.0;  ///< registration time
  int iterations = 0;
  std::size_t points = 0, pairs = 0;
  double error = 0.0;    ///< mean distance of the final correspondences, m
  bool bridged = false;  ///< the scan could not be registered: the motion prior was used
  /// The scans left the step open and the motion prior chose along it (open_step_window).
  bool open_step_from_prior = false;
  /// The long search ran (long_search_window), and whether its pose won.
  bool long_search = false, long_search_won = false;
  /// Few points fit even after the wide search (full_turn_search_below): the step's rotation is
  /// in doubt, whichever search won.
  bool weak_fit = false;
  /// Share of the points within 15 cm of the reference's surfaces at the searched pose (before
  /// the fine stage); -1 where no search ran. The step's health beside its error.
  double fit = -1.0;
  /// The scan fit its reference too poorly to be one (reference_fit_below) ...
  bool unfit = false;
  /// ... and was kept from being the next scan's reference (max_unfit_references_skipped).
  bool unfit_reference = false;
  /// The scan was unfit and its registration departed far from a steady motion: bridged by that
  /// motion (unfit_max_correction).
  bool steady_prior = false;

  /// The odometry could not register the scan (bridged, or unfit): loop closure holds its step
  /// loosely (LoopClosure2D::add_scan's `unfit`).
  bool unregistered() const { return bridged || unfit; }
};

template <typename Stats, typename Visitor>
requires std::same_as<std::remove_const_t<Stats>, Scan2DStats>
void describe(Stats& s, Visitor& v) {
  v.stage("ms", s.ms, "registration", "the scan's registration (Mapper2D::add_scan), ms");
  v("iterations", s.iterations, "registration iterations");
  v("points", s.points, "points of the scan registered");
  v("pairs", s.pairs, "correspondences of the last iteration");
  v("error_m", s.error, "mean distance of the final correspondences, m");
  v("bridged", s.bridged, "the scan could not be registered: the motion prior was used");
  v("open_step_from_prior", s.open_step_from_prior,
    "the scans left the step open and the motion prior chose along it (open_step_window)");
  v("fit", s.fit,
    "share of the points within 15 cm of the reference's surfaces at the searched pose, before "
    "the fine stage (-1: no search ran)");
  v("weak_fit", s.weak_fit,
    "few points fit even after the wide search (full_turn_search_below): the step's rotation is "
    "in doubt");
  v("long_search", s.long_search, "the long search ran (long_search_window)");
  v("long_search_won", s.long_search_won, "the long search's pose won");
  v("unfit", s.unfit, "the scan fit its reference too poorly to be one (reference_fit_below)");
  v("unfit_reference", s.unfit_reference,
    "the scan fit too poorly to be the next scan's reference (reference_fit_below)");
  v("steady_prior", s.steady_prior,
    "the scan was unfit and departed far from a steady motion: bridged by it "
    "(unfit_max_correction)");
}

}  // namespace scanmatch
