#pragma once
// The frame loop our odometry pipelines share (CtfIcpOdometry, FrameToFrameOdometry): the motion
// prior, preprocessing (with deskewing once the velocity is measured), the gate against the prior,
// the record of motion, and the reported pose. A pipeline supplies only the registration of a
// preprocessed frame and what the next frame registers against.
//
// Poses: internally each frame's pose is its mid-frame pose when frames carry point times (the
// deskew reference, and the average of a distorted frame's instants), the frame start otherwise.
// The reported pose is the frame-start pose, half the frame's motion earlier, in the world frame
// anchored at frame 0's start.

#include <array>
#include <cstddef>

#include "scanmatch/odometry/elevation_estimate.hpp"
#include "scanmatch/odometry/frame_odometry.hpp"
#include "scanmatch/odometry/motion_model.hpp"
#include "scanmatch/odometry/preprocessor.hpp"

namespace scanmatch {

class OdometryPipeline : public FrameOdometry {
 public:
  /// Never throws for bad frames: an empty or unregistrable frame is bridged by the motion prior
  /// (last_stats().bridged).
  Pose register_frame(const PointCloud& frame, double timestamp) final;
  const FrameStats& last_stats() const final { return stats_; }
  const PointCloud* last_map_frame(Pose& registration_from_frame) const final;
  Pose world_from_registration() const final { return world_from_internal_; }
  /// The world anchor is set at frame 1 and refined up to frame 4 (settle_early_frames).
  std::size_t world_settles_after() const final { return kWorldSettlesAfter; }
  Pose settled_pose(std::size_t index) const final;
  const PointCloud* settled_first_frame() const final {
    return settled_first_frame_.empty() ? nullptr : &settled_first_frame_;
  }

  const OdometryConfig& config() const { return config_; }
  std::size_t frames() const { return frames_; }
  /// The last frame's internal pose; world_from_internal() * it is its pose in the world frame.
  const Pose& last_internal_pose() const { return pose_; }
  const Pose& world_from_internal() const { return world_from_internal_; }
  /// The last registered frame, preprocessed and deskewed, in its sensor frame at the internal
  /// pose's instant.
  virtual const PointCloud& last_frame() const = 0;

 protected:
  /// `keep_attributes`: the preprocessed frame keeps rings and intensities; `map_points`: sparse
  /// frames are also kept at map density for update_reference; `deskews_again`: the pipeline's
  /// registration is trusted to deskew a frame again by (config redeskew_*) and to extrapolate the
  /// world anchor from. A registration
  /// noisier than the constant-velocity prior would only add its noise to the frame (loam frame to
  /// frame on dynamic-outdoor-fast: 0.67 -> 1.16 m over 20 frames).
  OdometryPipeline(const OdometryConfig& config, bool keep_attributes, bool map_points,
                   bool deskews_again);

  /// The internal pose of `frame` (preprocessed) from the motion prior, `predicted` being the last
  /// pose moved by it; frames() > 0. Sets `stats` (stage times, iterations, diagnostics; bridged
  /// when it returns the prediction for want of a registration). May throw Error (then bridged).
  virtual Pose estimate(const PointCloud& frame, const MotionPrior& prior, const Pose& predicted,
                        FrameStats& stats) = 0;
  /// The frame's pose is settled (`bridged`: the prediction): update what the next frame
  /// registers against.
  /// `map_points`: the frame at map density (Preprocessor::process), empty when `frame` serves.
  virtual void update_reference(PointCloud frame, const PointCloud& map_points, const Pose& pose,
                                bool bridged, FrameStats& stats) = 0;
  /// Waits for an update_reference still running beside the caller (a pipeline may run it on
  /// another thread while the next frame is read and preprocessed); rethrows its exception.
  /// Called before the next frame's estimate.
  virtual void finish_reference_update() {}
  /// Whether `estimate` lies within the motion model's gate around `predicted`.
  bool within_gate(const Pose& predicted, const Pose& estimate) const {
    return motion_.within_gate(predicted, estimate);
  }
  /// Forget every reference and start again from `first` (preprocessed, deskewed) as frame 0, at
  /// the internal origin: the first frame, deskewed once the first motion is measured.
  /// Only pipelines constructed with `deskews_again` are asked.
  virtual void restart_reference(PointCloud /*first*/, const PointCloud& /*map_points*/) {}
  /// Frame 0 at map density (Preprocessor's map points), given before frame 0's reference is
  /// set (again, when it is restarted): the one frame a young map holds, in more detail than its
  /// voxels get from the registration points. Only pipelines constructed with `deskews_again`.
  virtual void set_first_frame_detail(PointCloud /*detail*/) {}

 private:
  /// Deskews `frame` again by the motion registration measured, where that misses the motion it
  /// was deskewed by (config redeskew_*), and registers it again from `estimate`; at the second
  /// frame, deskews the first one too and restarts the reference from it. Returns the pose and
  /// replaces `down` with the frame as registered.
  Pose deskew_again(const PointCloud& frame, const MotionPrior& prior, bool deskewed,
                    const Pose& estimate, PointCloud& down);

  static constexpr std::size_t kWorldSettlesAfter = 5;

  /// The parts of a motion (log) that anchor the world: those of the first measured motion above
  /// anchor_min_*.
  Vector6d anchored_part(const Vector6d& motion) const;
  /// Where a frame's points are deskewed to and its pose taken, as a share of the time step from
  /// the last frame: the middle of the step where frames follow one another (kContiguousSweeps),
  /// else the middle of the frame's own sweep. Keyframes seconds apart were moved half their step
  /// ahead (a car's frame 5 m along an extrapolated motion), and each motion's error with them:
  /// campus-os1 keyframes 3-14 m apart 26.5 % of the path.
  double middle_share() const;
  /// The time step from the last frame is longer than kContiguousSweeps sweeps (keyframes).
  bool long_time_step() const;
  /// rad: how far the coarse stage's turned starts reach after a long time step.
  double turn_reach() const;
  /// `motion` over the time step from the last frame, deskewing to middle_share() of it.
  FrameMotion over_time_step(const Pose& motion) const;
  /// The world anchor and the early frames' start poses from the motions measured so far.
  void settle_early_frames();
  /// Offers the pair of the last registered frame and `frame` (preprocessed, at pose_) to the
  /// elevation estimate; once it decides, later frames are preprocessed with its correction.
  void offer_elevation_pair(const PointCloud& frame);
  /// `frame` cropped, deskewed by `motion` (when given) and filtered at map density.
  PointCloud frame_detail(const PointCloud& frame, const FrameMotion* motion) const;

  OdometryConfig config_;
  Preprocessor preprocessor_;
  MotionModel motion_;
  Pose pose_ = Pose::Identity();  ///< internal pose of the last frame
  Pose world_from_internal_ = Pose::Identity();
  std::size_t frames_ = 0;
  bool timed_frames_ = false;
  bool wants_map_points_;
  bool deskews_again_;
  PointCloud map_points_;  ///< the last frame at map density (reused between frames)
  Vector6d first_velocity_ = Vector6d::Zero();  ///< log of the first measured motion
  double first_sweep_ = 0.0;                    ///< s: frame 0's latest point time
  PointCloud first_frame_;  ///< frame 0 as given, until frame 1 has deskewed it (redeskew_*)
  PointCloud settled_first_frame_;  ///< frame 0 deskewed at frame 1, until the world settles
  /// Frame-start poses of the frames before the world settles, in the internal frame.
  std::array<Pose, kWorldSettlesAfter> early_starts_{};
  std::array<Pose, kWorldSettlesAfter> early_middles_{};  ///< their internal (mid-frame) poses
  /// Logs of the early frames' measured motions (mid-frame i-1 to i, at index i).
  std::array<Vector6d, kWorldSettlesAfter> early_velocities_{};
  std::array<double, kWorldSettlesAfter> early_middle_shares_{};  ///< their middle_share()
  /// Early frames 1..this follow one another unbridged: their motions are fitted together.
  std::size_t early_fitted_ = 0;
  FrameStats stats_;
  bool estimating_elevation_;
  ElevationEstimate elevation_;
  PointCloud elevation_previous_;  ///< the last frame offered, until the estimate decides
  Pose elevation_previous_pose_ = Pose::Identity();
  double elevation_previous_correction_ = 0.0;  ///< rad, what it was preprocessed with
};

}  // namespace scanmatch
