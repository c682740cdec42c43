#pragma once
// CTF-ICP (docs/methods.md section 1), one stage per file:
//   preprocessor.hpp  range crop, deskew, adaptive voxel filter (the shared frame loop runs it)
//   motion_model.hpp  the prior, its uncertainty and the gate (the shared frame loop)
//   coarse_ndt.hpp    NDT frame-to-frame from the prior, other starts under an uncertain prior
//   fine_stage.hpp    frame-to-map on the planar Gaussians, degeneracy guard
//   map_update.hpp    the global Gaussian map around the sensor
// This file only chains them.

#include <future>
#include <optional>

#include "scanmatch/odometry/coarse_ndt.hpp"
#include "scanmatch/odometry/fine_stage.hpp"
#include "scanmatch/odometry/map_update.hpp"
#include "scanmatch/odometry/odometry_pipeline.hpp"

namespace scanmatch {

class CtfIcpOdometry final : public OdometryPipeline {
 public:
  /// Throws Error for invalid parameters.
  explicit CtfIcpOdometry(const OdometryConfig& config);
  const PointCloud& last_frame() const override {
    wait_for_reference();
    return coarse_.reference();
  }
  /// The global Gaussian map, in the internal world frame (world_from_internal() * x gives the
  /// world frame of the returned poses).
  const GaussianVoxelMap& map() const {
    wait_for_reference();
    return map_.map();
  }

 private:
  Pose estimate(const PointCloud& frame, const MotionPrior& prior, const Pose& predicted,
                FrameStats& stats) override;
  /// The first motion, where little of the frame overlaps the last one at `estimate`:
  /// the frame registered onto the last one with no prior and refined against `target` from
  /// there; `estimate` unless that overlaps the last frame clearly more.
  Pose global_start(const PointCloud& frame, const GaussianVoxelMap& target, bool young_map,
                    const Pose& estimate, FrameStats& stats);
  /// Share of the frame's points within the global stage's feature voxel of the last frame.
  double overlap_with_last(const PointCloud& frame, const Pose& pose) const;
  void update_reference(PointCloud frame, const PointCloud& map_points, const Pose& pose,
                        bool bridged, FrameStats& stats) override;
  void restart_reference(PointCloud first, const PointCloud& map_points) override;
  void set_first_frame_detail(PointCloud detail) override;
  void finish_reference_update() override { wait_for_reference(); }
  void wait_for_reference() const;

  CoarseNdt coarse_;
  FineStage fine_;
  MapUpdate map_;
  std::optional<MapUpdate> first_frame_map_;  ///< frame 0 at map density, for frame 1's fine stage
  bool fine_stage_;
  /// Work still running; a copy of the pipeline (taken once it finished: map() waits) starts
  /// with none.
  struct Pending {
    std::future<void> work;
    Pending() = default;
    Pending(const Pending&) {}
    Pending& operator=(const Pending&) { return *this; }
  };
  /// With more than one thread, from frame 2 on, a frame's map update and NDT grid run beside
  /// the reading and preprocessing of the next frame (same results: nothing there reads them).
  /// Declared last: destroyed (joined) before what it writes.
  mutable Pending reference_update_;
};

}  // namespace scanmatch
