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
Pose2 correlative_search(const Scan2D& current, const Scan2D& reference, const Pose2& initial,
                         double window, double angle_window, double resolution = 0.05);

}  // namespace scanmatch
