#pragma once
// What the odometry's adaptive rules (adaptive.hpp) keep between frames.

#include "scanmatch/core/se3.hpp"

namespace scanmatch {

/// The prediction of one frame's motion from the last one.
struct MotionPrior {
  Pose motion = Pose::Identity();  ///< predicted motion from the last frame's pose
  double scale = 1.0;              ///< time-step ratio applied to the last motion
  bool uncertain = false;          ///< the coarse stage tries other starts; the gate widens
};

/// What the adaptive rules remember between frames.
struct AdaptiveState {
  double velocity_period = 0.0;  ///< s spanned by the last motion (0: unknown)
  bool previous_bridged = false;
  bool previous_missed = false;  ///< the last estimate was far from its prior
  MotionPrior prior;             ///< of the frame being registered
};

}  // namespace scanmatch
