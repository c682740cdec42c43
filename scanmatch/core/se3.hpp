#pragma once
// SO(3)/SE(3) helpers on Eigen. Poses are Eigen::Isometry3d. Tangent vectors are ordered
// [rotation (3); translation (3)], and exp/log are the exact group maps (not the "decoupled"
// rotation + translation form), so interpolation follows the screw motion.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>

namespace scanmatch {

using Pose = Eigen::Isometry3d;
using Vector6d = Eigen::Matrix<double, 6, 1>;

/// Degrees in one radian (for reports; angles are radians everywhere else).
inline constexpr double kDegreesPerRadian = 57.29577951308232;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

/// [v]_x: the matrix with skew(v) * w == v.cross(w).
inline Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d S;
  S << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return S;
}

/// Rodrigues: rotation by angle |w| about w / |w|; exact near zero.
Eigen::Matrix3d so3_exp(const Eigen::Vector3d& w);
/// Inverse of so3_exp, angle in [0, pi]; stable near 0 and pi.
Eigen::Vector3d so3_log(const Eigen::Matrix3d& R);
/// Left Jacobian of SO(3) (maps translation tangent to translation in se3_exp).
Eigen::Matrix3d so3_left_jacobian(const Eigen::Vector3d& w);

/// exp of xi = [w; v].
Pose se3_exp(const Vector6d& xi);
/// log of T as [w; v].
Vector6d se3_log(const Pose& T);

/// Geodesic interpolation: s = 0 gives a, s = 1 gives b; T = a * exp(s * log(a^-1 b)).
Pose interpolate(const Pose& a, const Pose& b, double s);

/// Rotation angle of T in radians, and translation norm in metres.
double rotation_angle(const Pose& T);
double translation_norm(const Pose& T);

Pose from_matrix(const Eigen::Matrix4d& M);  ///< Re-orthonormalises the rotation block.
Eigen::Matrix4d to_matrix(const Pose& T);

/// Quaternion order of TUM files: (qx, qy, qz, qw); normalised on the way in.
Pose from_translation_quaternion(const Eigen::Vector3d& t, const Eigen::Quaterniond& q);

/// KITTI pose row: r11 r12 r13 tx r21 r22 r23 ty r31 r32 r33 tz.
Pose from_kitti_row(const std::array<double, 12>& row);
std::array<double, 12> to_kitti_row(const Pose& T);

/// x, y, z and roll, pitch, yaw in radians (R = Rz(yaw) Ry(pitch) Rx(roll)).
Pose from_xyz_rpy(double x, double y, double z, double roll, double pitch, double yaw);
/// Inverse of from_xyz_rpy, pitch in [-pi/2, pi/2].
Eigen::Matrix<double, 6, 1> to_xyz_rpy(const Pose& T);

/// T with its rotation block projected back onto SO(3) (via a normalised quaternion): products of
/// many poses drift from orthonormality, and feedback loops (velocity priors) amplify that drift.
Pose orthonormalized(const Pose& T);

/// True when every entry is finite and the rotation block is orthonormal within `tolerance`.
bool is_valid_pose(const Eigen::Matrix4d& M, double tolerance = 1e-6);

}  // namespace scanmatch
