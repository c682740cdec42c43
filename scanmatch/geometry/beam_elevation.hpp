#pragma once
// A spinning sensor's beam elevations: a calibration error turns every beam up or down by about
// the same angle, and a flat floor comes out as a shallow cone (IMLS-SLAM corrects KITTI's
// HDL-64E scans by 0.22 deg). The simulator's sensors can carry such an error
// (SimOptions::elevation_bias_deg) and the odometry can take it out
// (OdometryConfig::elevation_correction_deg).

#include <Eigen/Core>
#include <cmath>

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

}  // namespace scanmatch
