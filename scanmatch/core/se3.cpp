#include "scanmatch/core/se3.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

namespace scanmatch {

Eigen::Matrix3d so3_exp(const Eigen::Vector3d& w) {
  const double theta2 = w.squaredNorm();
  const Eigen::Matrix3d W = skew(w);
  double a, b;  // R = I + a W + b W^2
  if (theta2 < 1e-10) {
    a = 1.0 - theta2 / 6.0;
    b = 0.5 - theta2 / 24.0;
  } else {
    const double theta = std::sqrt(theta2);
    a = std::sin(theta) / theta;
    b = (1.0 - std::cos(theta)) / theta2;
  }
  return Eigen::Matrix3d::Identity() + a * W + b * W * W;
}

Eigen::Vector3d so3_log(const Eigen::Matrix3d& R) {
  // The quaternion route is stable over the whole range including angles near pi.
  Eigen::Quaterniond q(R);
  q.normalize();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  const double vnorm = q.vec().norm();
  if (vnorm < 1e-12) return 2.0 * q.vec() / q.w();  // first order: theta ~ 2|v|/w
  const double theta = 2.0 * std::atan2(vnorm, q.w());
  return theta / vnorm * q.vec();
}

Eigen::Matrix3d so3_left_jacobian(const Eigen::Vector3d& w) {
  const double theta2 = w.squaredNorm();
  const Eigen::Matrix3d W = skew(w);
  double b, c;  // J = I + b W + c W^2
  if (theta2 < 1e-10) {
    b = 0.5 - theta2 / 24.0;
    c = 1.0 / 6.0 - theta2 / 120.0;
  } else {
    const double theta = std::sqrt(theta2);
    b = (1.0 - std::cos(theta)) / theta2;
    c = (theta - std::sin(theta)) / (theta2 * theta);
  }
  return Eigen::Matrix3d::Identity() + b * W + c * W * W;
}

Pose se3_exp(const Vector6d& xi) {
  const Eigen::Vector3d w = xi.head<3>();
  Pose T = Pose::Identity();
  T.linear() = so3_exp(w);
  T.translation() = so3_left_jacobian(w) * xi.tail<3>();
  return T;
}

Vector6d se3_log(const Pose& T) {
  const Eigen::Vector3d w = so3_log(T.linear());
  Vector6d xi;
  xi.head<3>() = w;
  xi.tail<3>() = so3_left_jacobian(w).inverse() * T.translation();
  return xi;
}

Pose interpolate(const Pose& a, const Pose& b, double s) {
  return a * se3_exp(s * se3_log(a.inverse() * b));
}

double rotation_angle(const Pose& T) {
  return so3_log(T.linear()).norm();
}
double translation_norm(const Pose& T) {
  return T.translation().norm();
}

Pose from_matrix(const Eigen::Matrix4d& M) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(M.topLeftCorner<3, 3>(),
                                        Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d R = svd.matrixU() * svd.matrixV().transpose();
  if (R.determinant() < 0.0) {
    Eigen::Matrix3d U = svd.matrixU();
    U.col(2) *= -1.0;
    R = U * svd.matrixV().transpose();
  }
  Pose T = Pose::Identity();
  T.linear() = R;
  T.translation() = M.topRightCorner<3, 1>();
  return T;
}

Eigen::Matrix4d to_matrix(const Pose& T) {
  Eigen::Matrix4d M = Eigen::Matrix4d::Identity();
  M.topLeftCorner<3, 3>() = T.linear();
  M.topRightCorner<3, 1>() = T.translation();
  return M;
}

Pose from_translation_quaternion(const Eigen::Vector3d& t, const Eigen::Quaterniond& q) {
  Pose T = Pose::Identity();
  T.linear() = q.normalized().toRotationMatrix();
  T.translation() = t;
  return T;
}

Pose from_kitti_row(const std::array<double, 12>& row) {
  Eigen::Matrix4d M = Eigen::Matrix4d::Identity();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) M(r, c) = row[static_cast<std::size_t>(4 * r + c)];
  return from_matrix(M);
}

std::array<double, 12> to_kitti_row(const Pose& T) {
  const Eigen::Matrix4d M = to_matrix(T);
  std::array<double, 12> row{};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) row[static_cast<std::size_t>(4 * r + c)] = M(r, c);
  return row;
}

Pose from_xyz_rpy(double x, double y, double z, double roll, double pitch, double yaw) {
  Pose T = Pose::Identity();
  T.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

Eigen::Matrix<double, 6, 1> to_xyz_rpy(const Pose& T) {
  const Eigen::Matrix3d& R = T.linear();
  Eigen::Matrix<double, 6, 1> out;
  out.head<3>() = T.translation();
  const double pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  double roll, yaw;
  if (std::abs(R(2, 0)) < 1.0 - 1e-12) {
    roll = std::atan2(R(2, 1), R(2, 2));
    yaw = std::atan2(R(1, 0), R(0, 0));
  } else {  // gimbal lock: put all of the remaining rotation into yaw
    roll = 0.0;
    yaw = std::atan2(-R(0, 1), R(1, 1));
  }
  out(3) = roll;
  out(4) = pitch;
  out(5) = yaw;
  return out;
}

Pose orthonormalized(const Pose& T) {
  Pose out = T;
  out.linear() = Eigen::Quaterniond(T.linear()).normalized().toRotationMatrix();
  return out;
}

bool is_valid_pose(const Eigen::Matrix4d& M, double tolerance) {
  if (!M.allFinite()) return false;
  const Eigen::Matrix3d R = M.topLeftCorner<3, 3>();
  if ((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > tolerance)
    return false;
  if (std::abs(R.determinant() - 1.0) > tolerance) return false;
  return std::abs(M(3, 0)) + std::abs(M(3, 1)) + std::abs(M(3, 2)) + std::abs(M(3, 3) - 1.0) <=
         tolerance;
}

}  // namespace scanmatch
