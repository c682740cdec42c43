// A minimal stand-in for the parts of Sophus (SO3d, SE3d) that KISS-ICP's C++ core uses, written
// for this machine because Debian 12 has no Sophus package. Tangent order as in Sophus:
// SE3 = [translation (upsilon); rotation (omega)].
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

namespace Sophus {

class SO3d {
 public:
  using Tangent = Eigen::Vector3d;
  SO3d() : q_(Eigen::Quaterniond::Identity()) {}
  explicit SO3d(const Eigen::Quaterniond& q) : q_(q.normalized()) {}
  explicit SO3d(const Eigen::Matrix3d& R) : q_(Eigen::Quaterniond(R).normalized()) {}

  static Eigen::Matrix3d hat(const Eigen::Vector3d& w) {
    Eigen::Matrix3d m;
    m << 0.0, -w.z(), w.y(), w.z(), 0.0, -w.x(), -w.y(), w.x(), 0.0;
    return m;
  }
  static SO3d exp(const Eigen::Vector3d& w) {
    const double theta = w.norm();
    if (theta < 1e-12) {
      Eigen::Quaterniond q(1.0, 0.5 * w.x(), 0.5 * w.y(), 0.5 * w.z());
      return SO3d(q);
    }
    return SO3d(Eigen::Quaterniond(Eigen::AngleAxisd(theta, w / theta)));
  }
  static SO3d rotX(double a) { return exp(Eigen::Vector3d(a, 0.0, 0.0)); }
  static SO3d rotY(double a) { return exp(Eigen::Vector3d(0.0, a, 0.0)); }
  static SO3d rotZ(double a) { return exp(Eigen::Vector3d(0.0, 0.0, a)); }

  Eigen::Vector3d log() const {
    Eigen::Quaterniond q = q_;
    if (q.w() < 0.0) q.coeffs() = -q.coeffs();  // shortest rotation
    const double n = q.vec().norm();
    if (n < 1e-12) return 2.0 * q.vec() / q.w();
    const double theta = 2.0 * std::atan2(n, q.w());
    return theta / n * q.vec();
  }
  SO3d inverse() const { return SO3d(q_.conjugate()); }
  Eigen::Matrix3d matrix() const { return q_.toRotationMatrix(); }
  const Eigen::Quaterniond& unit_quaternion() const { return q_; }
  SO3d operator*(const SO3d& o) const { return SO3d(q_ * o.q_); }
  Eigen::Vector3d operator*(const Eigen::Vector3d& p) const { return q_ * p; }

 private:
  Eigen::Quaterniond q_;
};

using SO3 = SO3d;

}  // namespace Sophus
