#pragma once
// When a frame's health record (frame_stats.hpp) says "do not trust this frame": the thresholds
// summary.json's `health` counts with and the report draws. One place, so that the counts and
// the plots cannot disagree.

#include "scanmatch/odometry/frame_stats.hpp"

namespace scanmatch::health {

/// Below this share of its points paired with map planes the fine stage has too thin a map (or
/// too new a view) to hold the pose. 0 means "not measured" (frame-to-frame methods).
inline constexpr double kThinPairedFraction = 0.3;
/// The fine stage moved the coarse result by more than this: the stages disagree.
inline constexpr double kDisagreementM = 0.25;
inline constexpr double kDisagreementDeg = 3.0;

inline bool thin_map(const FrameStats& f) {
  return f.fine_paired_fraction > 0.0 && f.fine_paired_fraction < kThinPairedFraction;
}
inline bool stages_disagree(const FrameStats& f) {
  return f.coarse_fine_m > kDisagreementM || f.coarse_fine_deg > kDisagreementDeg;
}

}  // namespace scanmatch::health
