#pragma once
// What one frame of odometry reports: stage times, point counts and the solver's diagnostics.

#include <cstddef>

namespace scanmatch {

struct FrameStats {
  double preprocess_ms = 0, coarse_ms = 0, fine_ms = 0, map_ms = 0, total_ms = 0;
  std::size_t points_in = 0, points_downsampled = 0;
  int iterations = 0;             ///< coarse plus fine
  double condition_number = 0;    ///< of the last stage's information matrix
  int degenerate_directions = 0;  ///< directions the fine stage left at the motion prior
  bool bridged = false;           ///< the frame could not be registered: the motion prior was used
};

}  // namespace scanmatch
