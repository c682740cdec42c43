#pragma once
// LiDAR sensor models: each a generator of ray directions, per-ray time offsets within the frame
// and rings, with range limits, range noise and dropouts (the table in docs/methods.md).

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

namespace scanmatch::sim {

enum class ScanPattern { kSpinning, kLivoxMid360, kLivoxRosette, kPlanar };

struct SensorModel {
  std::string name;
  ScanPattern pattern = ScanPattern::kSpinning;
  double rate_hz = 10.0;
  std::size_t rays_per_frame = 0;
  int rings = 0;                                        ///< spinning sensors; 0 otherwise
  double elevation_min_deg = 0, elevation_max_deg = 0;  ///< vertical field of view
  double horizontal_fov_deg = 360;
  double min_range = 0.1, max_range = 100.0;  ///< m
  double high_reflectivity_max_range = 0.0;   ///< m at reflectivity 0.8 (0: same as max_range)
  double range_noise = 0.02;                  ///< m, standard deviation
  double range_noise_fraction = 0.0;          ///< plus this fraction of the range (2D lasers)
  double dropout = 0.01;                      ///< probability a return is lost
  /// s per turn of a planar laser's mirror (0: one turn per frame, as the Neato). A SICK LMS
  /// turns at 75 Hz whatever rate its scans are logged at, so its scans hardly smear.
  double mirror_period = 0.0;
  double frame_period() const { return 1.0 / rate_hz; }
  double rotation_period() const { return mirror_period > 0.0 ? mirror_period : frame_period(); }
  bool is_2d() const { return pattern == ScanPattern::kPlanar; }
  bool is_full_turn() const { return horizontal_fov_deg >= 360.0; }
  /// Planar lasers: the first beam's angle and the angle between beams (rad, sensor frame). A
  /// full turn starts at 0 (n beams around); a partial field of view is centred on x, its n beams
  /// spanning it end to end (a SICK LMS: 181 beams from -90 to +90 deg).
  double planar_angle_min() const;
  double planar_angle_increment() const;
};

/// mid360, avia, vlp16, hdl64, os1-64, neato, sick-lms. Throws Error naming the valid ones.
const SensorModel& sensor_model(const std::string& name);
std::vector<std::string> sensor_names();

/// The rays of one frame, in the sensor frame.
struct RayPattern {
  std::vector<Eigen::Vector3f> directions;  ///< unit vectors, x forward, z up
  std::vector<float> times;                 ///< s since the frame start
  std::vector<std::uint16_t> rings;         ///< ring per ray (spinning sensors; else laser index)
};

/// Rays of frame `frame_index`. Non-repetitive patterns continue from frame to frame (the prisms
/// keep turning), so consecutive frames differ and coverage grows when frames are accumulated.
void generate_pattern(const SensorModel& sensor, std::uint64_t frame_index, RayPattern& pattern);

}  // namespace scanmatch::sim
