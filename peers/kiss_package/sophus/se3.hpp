// A minimal stand-in for Sophus::SE3d (see so3.hpp).
#pragma once

#include "so3.hpp"

namespace Sophus {

class SE3d {
 public:
  using Tangent = Eigen::Matrix<double, 6, 1>;
  SE3d() : t_(Eigen::Vector3d::Zero()) {}
  SE3d(const SO3d& R, const Eigen::Vector3d& t) : R_(R), t_(t) {}
  SE3d(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) : R_(R), t_(t) {}
  SE3d(const Eigen::Quaterniond& q, const Eigen::Vector3d& t) : R_(q), t_(t) {}
  explicit SE3d(const Eigen::Matrix4d& T)
      : R_(Eigen::Matrix3d(T.topLeftCorner<3, 3>())), t_(T.topRightCorner<3, 1>()) {}

  // V = I + (1 - cos t)/t^2 W + (t - sin t)/t^3 W^2, the left Jacobian of SO(3).
  static Eigen::Matrix3d left_jacobian(const Eigen::Vector3d& w) {
    const double theta2 = w.squaredNorm();
    const Eigen::Matrix3d W = SO3d::hat(w);
    if (theta2 < 1e-10) return Eigen::Matrix3d::Identity() + 0.5 * W + W * W / 6.0;
    const double theta = std::sqrt(theta2);
    return Eigen::Matrix3d::Identity() + (1.0 - std::cos(theta)) / theta2 * W +
           (theta - std::sin(theta)) / (theta2 * theta) * W * W;
  }
  static Eigen::Matrix3d left_jacobian_inverse(const Eigen::Vector3d& w) {
    const double theta2 = w.squaredNorm();
    const Eigen::Matrix3d W = SO3d::hat(w);
    if (theta2 < 1e-10) return Eigen::Matrix3d::Identity() - 0.5 * W + W * W / 12.0;
    const double theta = std::sqrt(theta2);
    const double c = (1.0 - theta * std::sin(theta) / (2.0 * (1.0 - std::cos(theta)))) / theta2;
    return Eigen::Matrix3d::Identity() - 0.5 * W + c * W * W;
  }

  static SE3d exp(const Tangent& x) {
    const Eigen::Vector3d upsilon = x.head<3>(), omega = x.tail<3>();
    return SE3d(SO3d::exp(omega), left_jacobian(omega) * upsilon);
  }
  Tangent log() const {
    const Eigen::Vector3d omega = R_.log();
    Tangent x;
    x.head<3>() = left_jacobian_inverse(omega) * t_;
    x.tail<3>() = omega;
    return x;
  }

  SE3d inverse() const {
    const SO3d Rinv = R_.inverse();
    return SE3d(Rinv, -(Rinv * t_));
  }
  SE3d operator*(const SE3d& o) const { return SE3d(R_ * o.R_, t_ + R_ * o.t_); }
  Eigen::Vector3d operator*(const Eigen::Vector3d& p) const { return R_ * p + t_; }

  const SO3d& so3() const { return R_; }
  Eigen::Matrix3d rotationMatrix() const { return R_.matrix(); }
  const Eigen::Vector3d& translation() const { return t_; }
  Eigen::Vector3d& translation() { return t_; }
  Eigen::Quaterniond unit_quaternion() const { return R_.unit_quaternion(); }
  Eigen::Matrix4d matrix() const {
    Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
    T.topLeftCorner<3, 3>() = R_.matrix();
    T.topRightCorner<3, 1>() = t_;
    return T;
  }

 private:
  SO3d R_;
  Eigen::Vector3d t_;
};

using SE3 = SE3d;

}  // namespace Sophus
