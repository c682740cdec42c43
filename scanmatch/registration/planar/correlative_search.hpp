#pragma once
// Correlative scan matching over a window (Olson's idea, our own two-level branch and bound): the
// reference becomes a smoothed likelihood grid; each rotation of the current scan is scored at
// every translation of the window. A max-filtered copy of the grid bounds the score of a whole
// block of translations, so most blocks are dismissed without looking at their cells.
// register_scans runs it first when Registration2DOptions::search_window is set.

#include "scanmatch/core/scan2d.hpp"

namespace scanmatch {

/// The pose within +- `window` (m, in x and y) and +- `angle_window` (rad) of `initial` whose
/// transformed points best hit a smoothed likelihood grid of the reference, found exactly at the
/// grid's resolution (m; coarser when the area is huge). Throws Error unless the window and the
/// resolution are positive and the angle window is not negative; returns `initial` when no
/// reference point lies where the current scan can land.
/// With `fill_gap` (m, 0: off) the reference's surfaces are filled in first (filled_surfaces).
Pose2 correlative_search(const Scan2D& current, const Scan2D& reference, const Pose2& initial,
                         double window, double angle_window, double resolution = 0.05,
                         double fill_gap = 0.0);

/// The scan's points plus points every `step` (m) between beam neighbours up to `max_gap` apart
/// that lie on one straight surface (a third neighbour on their line). Two scans sample a wall
/// seen at a grazing angle at different places, metres apart; scored against the samples alone, a
/// scan fits best where its samples fall on the reference's, which along a corridor is where the
/// sensor did not move (steps came out short on ACES and Intel: docs/planar.md).
std::vector<Eigen::Vector2d> filled_surfaces(const Scan2D& scan, double max_gap, double step);

}  // namespace scanmatch
