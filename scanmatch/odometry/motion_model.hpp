#pragma once
// The motion model of the odometry: the prior of each frame's motion, how far it can be trusted,
// the gate a registration result must pass, and the record of past motion it learns from.
//
// - Constant velocity, time-scaled: the prior is the last measured motion, scaled by the ratio of
//   the frame time steps (keyframe folders have irregular steps). A steady sensor's steps within
//   jitter of its period count as the period (stamps from a coarse clock are not timing).
// - The prior is *uncertain* for the first registered frame, when the time stamps do not increase
//   or their ratio is outside [1/max_step_ratio, max_step_ratio], after a bridged frame, and after
//   a frame whose estimate missed its prior by more than prior_miss_distance / prior_miss_angle,
//   and when the prior turns more than uncertain_rotation in one step. An uncertain prior makes the
//   coarse stage try other starts and widens the gate by uncertain_jump_scale.
// - A bridged frame (no usable registration) keeps the last measured velocity: its own motion is
//   the prior itself, not a measurement.
//
// With regular time steps and an accurate prior, the prior is the last motion, unscaled.

#include <cstddef>
#include <deque>

#include "scanmatch/core/se3.hpp"
#include "scanmatch/odometry/odometry_config.hpp"

namespace scanmatch {

/// The prediction of one frame's motion from the last one.
struct MotionPrior {
  Pose motion = Pose::Identity();  ///< predicted motion from the last frame's pose
  double scale = 1.0;              ///< time-step ratio applied to the last motion
  bool uncertain = false;          ///< the coarse stage tries other starts; the gate widens
  /// The time step was more than max_step_ratio times the last one (a clamped scale): over such a
  /// gap the sensor may have stopped or slowed anywhere, so the gate spans the scaled motion.
  bool gap = false;
  /// rad, set after a time step longer than a sweep (keyframes; 0 otherwise): between such frames
  /// a vehicle turns farther than the coarse stage's basin (20 deg in 0.5 s at a corner), so a
  /// slow solve under a certain prior also tries the other starts, the turned ones reach this far
  /// to either side and are also tried bent along an arc (along_an_arc), and the gate also lies
  /// around the prior bent to the estimate's heading.
  double turn_reach = 0.0;
};

/// `motion` scaled along its own twist: factor 2 is the same motion twice (constant velocity).
Pose scaled_motion(const Pose& motion, double factor);
/// `motion` turned by `yaw` about the sensor's z axis at its end, its translation as it was.
Pose turned_about_z(const Pose& motion, double yaw);
/// turned_about_z with the translation turned by half of `yaw`: the same path length bent along
/// an arc, as a vehicle that turned `yaw` more on the way.
Pose along_an_arc(const Pose& motion, double yaw);

class MotionModel {
 public:
  explicit MotionModel(const OdometryConfig& config);

  /// Starts the next frame, taken at `timestamp` s, after `frames` registered ones: its prior.
  const MotionPrior& predict(double timestamp, std::size_t frames);
  /// Marks the frame just predicted as one after a long time step (MotionPrior::turn_reach).
  void set_turn_reach(double reach) { prior_.turn_reach = reach; }
  /// The prior of the frame being registered.
  const MotionPrior& prior() const { return prior_; }
  /// The last measured motion between two frames (identity before the second frame).
  const Pose& velocity() const { return velocity_; }
  /// The last positive time step between frames, s (0.1 until one is known).
  double frame_period() const { return frame_period_; }
  /// True when `estimate` is finite and lies within the gate around `predicted` (widened under an
  /// uncertain prior), or after a time gap within the gate around any fraction of the prior's
  /// motion (from standing still to going on as before).
  bool within_gate(const Pose& predicted, const Pose& estimate) const;
  /// Motion above `factor` times the deskew dead band (smaller motion is estimation noise).
  bool moving(const Pose& motion, double factor = 1.0) const;
  /// Records the frame's outcome: `motion` from the last pose, and whether it was bridged.
  void record(const Pose& motion, bool bridged);

 private:
  /// Scales prior_ by the ratio of this time step to the last motion's (uncertain beyond bounds).
  void scale_by_time_step();
  /// The mean of the recent time steps when they lie within jitter of it (a steady sensor), else 0.
  double steady_period() const;
  /// A steady sensor's `step` that lies within jitter of its period.
  bool within_steady_period(double step) const;
  /// `step`, or the steady period when it lies within jitter of it.
  double as_period(double step) const;
  void remember_step(double step);

  OdometryConfig config_;
  MotionPrior prior_;
  Pose velocity_ = Pose::Identity();
  double last_timestamp_ = 0.0, step_ = 0.0, frame_period_ = 0.1;
  double velocity_period_ = 0.0;     ///< s spanned by velocity_ (0: unknown)
  std::deque<double> recent_steps_;  ///< the last positive time steps, s
  double steady_period_ = 0.0;       ///< steady_period() before this frame's step (0: not steady)
  std::size_t odd_steps_ = 0;        ///< consecutive steps off the steady period
  bool previous_bridged_ = false;
  bool previous_missed_ = false;  ///< the last estimate was far from its prior
};

}  // namespace scanmatch
