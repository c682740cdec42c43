#pragma once
// A spinning sensor's beam elevations: a calibration error turns every beam up or down by about
// the same angle, and a flat floor comes out as a shallow cone (IMLS-SLAM corrects KITTI's
// HDL-64E scans by 0.22 deg). The simulator's sensors can carry such an error
// (SimOptions::elevation_bias_deg) and the odometry can take it out
// (OdometryConfig::elevation_correction_deg).

#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <limits>

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/core/se3.hpp"

namespace scanmatch {

/// Turns points up by a fixed angle in the vertical plane through the sensor's z axis and the
/// point: the same range and bearing, the elevation plus the angle.
class ElevationTurn {
 public:
  explicit ElevationTurn(double angle) : cos_(std::cos(angle)), sin_(std::sin(angle)) {}

  template <typename Scalar>
  Eigen::Matrix<Scalar, 3, 1> operator()(const Eigen::Matrix<Scalar, 3, 1>& p) const {
    const double x = p.x(), y = p.y(), z = p.z();
    const double horizontal = std::hypot(x, y);
    if (!(horizontal > 0.0)) return p;  // straight up or down: no bearing to turn in
    const double turned = horizontal * cos_ - z * sin_;
    const double scale = turned / horizontal;
    return Eigen::Matrix<Scalar, 3, 1>(static_cast<Scalar>(x * scale),
                                       static_cast<Scalar>(y * scale),
                                       static_cast<Scalar>(horizontal * sin_ + z * cos_));
  }

 private:
  double cos_, sin_;
};

/// What one pair of overlapping frames of a spinning sensor says of its beam elevation bias: the
/// angle by which the points' elevations exceed the beams' (an ElevationTurn of that angle made
/// the frames from the truth), solved jointly with the pair's relative pose. A flat floor seen from
/// two places is two cones about two apexes, which no rigid motion lays onto each other; the bias
/// that flattens both does.
struct ElevationBiasFromPair {
  double bias = 0.0;  ///< rad; positive: the points lie higher than the beams that measured them
  /// rad: the bias's marginal standard deviation (the pose's six directions eliminated) at the
  /// pair's own residual scale; infinite when the pair says nothing.
  double standard_error = std::numeric_limits<double>::infinity();
  std::size_t planes = 0;  ///< planar correspondences of the last iteration
};

/// Solves the pair: `source` (its sensor frame) lies at `source_in_target` in `target`'s sensor
/// frame, both as the sensor delivered them (not yet corrected). Points are paired with planes of
/// the target's nearest neighbours; surfaces seen from two ranges carry the signal (a car's steps
/// of metres: 0.03-0.1 deg per pair on 64 beams).
ElevationBiasFromPair estimate_elevation_bias(const PointCloud& target, const PointCloud& source,
                                              const Pose& source_in_target);

}  // namespace scanmatch
