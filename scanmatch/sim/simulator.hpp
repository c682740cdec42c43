#pragma once
// The LiDAR simulator: a preset (scene + sensor + motion) rendered frame by frame with exact
// ground truth, written as a data set or streamed as a SequenceSource (`sim:PRESET`).

#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>
#include <vector>

#include "scanmatch/io/carmen.hpp"
#include "scanmatch/io/sequence.hpp"
#include "scanmatch/io/trajectory.hpp"
#include "scanmatch/sim/motion.hpp"
#include "scanmatch/sim/sensor.hpp"
#include "scanmatch/sim/worlds.hpp"

namespace scanmatch::sim {

struct SimOptions {
  std::string preset = "dynamic-outdoor";
  std::string sensor;                 ///< empty: the preset's sensor
  std::optional<std::size_t> frames;  ///< truncate (or extend a still preset) to this many frames
  std::uint64_t seed = 1;
  /// Each point measured from the pose at its own time; false: every point from the frame's start
  /// pose, and frames carry no per-point time.
  bool motion_distortion = true;
  bool noise = true;  ///< range noise and dropouts
  /// A beam calibration error of 3D sensors: every point is reported this much higher in
  /// elevation (deg) than the beam that measured it (geometry/beam_elevation.hpp). 0: exact.
  double elevation_bias_deg = 0.0;
  std::string trajectory_file;  ///< replay this KITTI/TUM trajectory instead of the preset's path
  /// Replay this trajectory (anchored like trajectory_file); wins over trajectory_file.
  std::optional<Trajectory> trajectory;
};

struct PresetInfo {
  std::string name, scene, sensor, motion, description;
  std::size_t frames = 0;
  double path_length = 0.0;  ///< m, 0 for still presets
};
const std::vector<PresetInfo>& presets();
/// Scenes for planar lasers (rooms-2d, corridors-2d): they go with 2D sensors only.
bool is_2d_scene(const std::string& scene);
/// Throws Error naming the valid presets.
const PresetInfo& preset_info(const std::string& name);

class Simulator {
 public:
  explicit Simulator(const SimOptions& options);

  std::size_t size() const { return frames_; }
  const SensorModel& sensor() const { return *sensor_; }
  const PresetInfo& preset() const { return *preset_; }
  const SimOptions& options() const { return options_; }
  const World& world() const { return world_; }
  double frame_time(std::size_t i) const {
    return static_cast<double>(i) * sensor_->frame_period();
  }

  /// Sensor pose in the scene at time t (s since the first frame).
  Pose scene_pose_at(double t) const { return motion_.at(t); }
  /// Ground truth of frame i: sensor pose at the frame's start in the world frame of frame 0.
  Pose pose(std::size_t i) const;
  Trajectory ground_truth() const;
  double path_length() const;

  /// Frame i: x y z intensity ring t, points in the sensor frame at their own measurement time.
  PointCloud frame(std::size_t i) const;
  /// Frame i of a 2D sensor as a CARMEN scan (ranges over 360 degrees, max_range = no return).
  LaserScan2D scan_2d(std::size_t i) const;

 private:
  SimOptions options_;
  const PresetInfo* preset_;
  const SensorModel* sensor_;
  World world_;
  DenseTrajectory motion_;
  std::size_t frames_ = 0;
  Pose first_inverse_ = Pose::Identity();
};

/// What write_dataset writes beyond the simulator's own frames.
struct DatasetSelection {
  std::vector<std::size_t> frames;  ///< frame indices, ascending (empty: every frame)
  /// Applied to each 3D frame (with its index) before it is written; empty: as simulated.
  std::function<PointCloud(PointCloud, std::size_t)> prepare;
  /// Adds fields to dataset.json; empty: none.
  std::function<void(nlohmann::ordered_json&)> describe;
};

/// Writes frames/NNNNNN.pcd (named by frame index; scans.log for 2D), poses_gt.txt,
/// poses_gt_tum.txt, times.txt and dataset.json into `folder` (created). Progress on a terminal
/// unless `quiet`.
void write_dataset(const Simulator& simulator, const std::string& folder, bool quiet,
                   const DatasetSelection& selection = {});

/// The preset of `options` as a SequenceSource whose frames are simulated on the fly (what
/// `sim:PRESET` opens: see open_sequence in scanmatch/sim/open_sequence.hpp).
std::unique_ptr<SequenceSource> simulated_sequence(const SimOptions& options);

}  // namespace scanmatch::sim
