#pragma once
// Point times for frames of a spinning LiDAR that carry none (KITTI .bin scans, clouds saved
// without their time field): a spinning sensor measures each azimuth at a known instant of its
// turn, so a point's time follows from its azimuth alone. Deskewing (preprocessor.hpp) needs them.

#include <cmath>

#include "scanmatch/core/point_cloud.hpp"

namespace scanmatch {

/// How a spinning sensor's sweep maps azimuth to time. Azimuth is atan2(y, x) in the sensor frame
/// (0 along +x, counter-clockwise positive seen from above, z up).
struct SpinTiming {
  double period = 0.1;  ///< s per turn (one frame)
  /// rad: where the sweep starts (and ends, a turn later). The defaults here are KITTI's HDL-64E,
  /// whose scans are cut behind the car and turn clockwise (docs/odometry.md measured both).
  double start_azimuth = M_PI;
  bool clockwise = true;  ///< seen from above: azimuth decreasing with time
};

/// Sets every point's time (s since the frame start, in [0, period]) to the instant the sweep
/// described by `timing` reaches the point's azimuth, replacing any time the cloud had. A point on
/// the sensor's axis (x = y = 0) or with a non-finite position gets NaN (no time: deskewing leaves
/// it as it is). A period that is not positive and finite leaves the cloud without times.
void assign_azimuth_times(PointCloud& cloud, const SpinTiming& timing);

}  // namespace scanmatch
