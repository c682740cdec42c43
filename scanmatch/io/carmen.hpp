#pragma once
// CARMEN logs, the format of the classic 2D laser SLAM data sets: FLASER, ROBOTLASER1 and ODOM
// records (read and write); other record types are counted and skipped. Their laser scans
// (LaserScan2D, also what the simulator's 2D sensor gives) become the 2D methods' Scan2D with
// scan_from_laser.

#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "scanmatch/core/scan2d.hpp"

namespace scanmatch {

struct LaserScan2D {
  double timestamp = 0.0;               ///< logger timestamp, s
  double angle_min = -M_PI / 2;         ///< rad, angle of the first beam in the laser frame
  double angle_increment = M_PI / 180;  ///< rad between beams
  /// m; readings >= max_range or <= 0 are "no return" (FLASER: 80 or the log's no-return reading,
  /// no_return_reading)
  float max_range = 80.0f;
  std::vector<float> ranges;                            ///< m
  std::vector<float> remissions;                        ///< optional
  Eigen::Vector3d pose = Eigen::Vector3d::Zero();       ///< x, y, theta of the laser in the log
  Eigen::Vector3d odom_pose = Eigen::Vector3d::Zero();  ///< robot odometry x, y, theta
};

/// Valid beams (finite, range in (min_range, max_range)) as points, in beam order; `circular`
/// when the beams cover the full circle. Beams at or beyond the maximum range become `misses`
/// at `miss_range` (0: the scan's max range). With `rotation_period` (s per turn of the laser's
/// mirror or head; 0: unknown) each point gets its time: beams are measured in order, one full
/// turn taking the period.
Scan2D scan_from_laser(const LaserScan2D& scan, double min_range = 0.05, double miss_range = 0.0,
                       double rotation_period = 0.0);

struct Odometry2D {
  double timestamp = 0.0;
  Eigen::Vector3d pose = Eigen::Vector3d::Zero();  ///< x, y, theta
  double tv = 0.0, rv = 0.0, accel = 0.0;
};

struct CarmenLog {
  std::vector<LaserScan2D> scans;
  std::vector<Odometry2D> odometry;
  std::size_t ignored_lines = 0;  ///< records of other types (PARAM, SYNC, ...)
};

struct CarmenReadOptions {
  /// FLASER records carry no angles: the laser's field of view, rad. Beams are spread over it as
  /// fov / (n - 1) for an odd count (181, 361) and fov / n for an even one (180, 360).
  double flaser_field_of_view = M_PI;
  /// FLASER: lower every scan's max_range to the log's own no-return reading (no_return_reading)
  /// where it shows one below 80 m: taken for returns, acapulco's 51.15 m codes made its open
  /// hall come out standing still (docs/planar.md).
  bool infer_no_return = true;
};

/// FLASER records carry no maximum range, and a laser reports "no return" as a reading of its
/// own: 81.83 or 81.91 m on intel and freiburg-campus, but also 50.0 (aces), 51.05 (fhw),
/// 51.15 (acapulco) or 32.767 m (orebro), which the default 80 m takes for returns: arcs of points
/// about the sensor that line up with the previous scan's where the sensor did not move (acapulco's
/// open hall came out standing still: docs/planar.md). Such a code is the reading the far end of
/// a log repeats: where at least half of the farthest 0.5 % of `scans`' readings (10 at least)
/// lie within 2 cm, readings from 2 cm below those count as no return, and that range is returned;
/// else none. With CarmenReadOptions::infer_no_return, read_carmen_log and parse_carmen_log lower
/// their FLASER scans' max_range to it.
std::optional<double> no_return_reading(const std::vector<LaserScan2D>& scans);

CarmenLog read_carmen_log(const std::string& path, const CarmenReadOptions& options = {});
/// Parses log text; `source_name` names it in errors.
CarmenLog parse_carmen_log(std::string_view text, const std::string& source_name,
                           const CarmenReadOptions& options = {});

enum class CarmenLaserRecord { kFlaser, kRobotLaser1 };
/// Whole-file atomic write; ROBOTLASER1 keeps the angles, FLASER is what old tools read.
void write_carmen_log(const std::string& path, const CarmenLog& log,
                      CarmenLaserRecord record = CarmenLaserRecord::kRobotLaser1);

}  // namespace scanmatch
