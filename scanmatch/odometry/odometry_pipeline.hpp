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

#include <cstddef>

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
  const PointCloud* last_map_frame(Pose& world_from_frame) const final;

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
  /// frames are also kept at map density for update_reference.
  OdometryPipeline(const OdometryConfig& config, bool keep_attributes, bool map_points);

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

 private:
  OdometryConfig config_;
  Preprocessor preprocessor_;
  MotionModel motion_;
  Pose pose_ = Pose::Identity();  ///< internal pose of the last frame
  Pose world_from_internal_ = Pose::Identity();
  std::size_t frames_ = 0;
  bool timed_frames_ = false;
  bool wants_map_points_;
  PointCloud map_points_;  ///< the last frame at map density (reused between frames)  ///< the
                           ///< first frame had point times: poses are mid-frame internally
  FrameStats stats_;
};

}  // namespace scanmatch
