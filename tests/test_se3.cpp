#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "scanmatch/core/se3.hpp"

using namespace scanmatch;

namespace {
Vector6d random_tangent(std::mt19937& rng, double rot_scale, double trans_scale) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Vector6d xi;
  for (int i = 0; i < 3; ++i) xi(i) = rot_scale * u(rng);
  for (int i = 3; i < 6; ++i) xi(i) = trans_scale * u(rng);
  return xi;
}
}  // namespace

TEST(So3, SkewIsCrossProduct) {
  const Eigen::Vector3d a(1.0, -2.0, 0.5), b(0.3, 4.0, -1.0);
  EXPECT_TRUE((skew(a) * b).isApprox(a.cross(b)));
  EXPECT_TRUE((skew(a) + skew(a).transpose()).isZero());
}

TEST(So3, ExpOfKnownRotation) {
  // 90 degrees about z maps x to y.
  const Eigen::Matrix3d R = so3_exp(Eigen::Vector3d(0, 0, M_PI / 2));
  EXPECT_TRUE((R * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-12));
  EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
}

TEST(So3, LogExpRoundTripIncludingNearZeroAndNearPi) {
  std::mt19937 rng(1);
  for (int k = 0; k < 200; ++k) {
    Eigen::Vector3d axis = random_tangent(rng, 1.0, 0.0).head<3>().normalized();
    for (double angle : {1e-9, 1e-4, 0.3, 2.0, M_PI - 1e-6}) {
      const Eigen::Vector3d w = angle * axis;
      const Eigen::Vector3d back = so3_log(so3_exp(w));
      EXPECT_TRUE(so3_exp(back).isApprox(so3_exp(w), 1e-9));
      if (angle < 3.0) {
        EXPECT_LT((back - w).norm(), 1e-9 * std::max(1.0, angle));
      }
    }
  }
}

TEST(Se3, ExpOfPureTranslationAndKnownScrew) {
  Vector6d xi = Vector6d::Zero();
  xi.tail<3>() = Eigen::Vector3d(1, 2, 3);
  EXPECT_TRUE(se3_exp(xi).translation().isApprox(Eigen::Vector3d(1, 2, 3)));
  // Screw about z: rotate by pi while translating 2 along x in the tangent; the exact group exp
  // moves along a half circle: t = J(w) v with J = I + (1-cos)/th^2 W + (th-sin)/th^3 W^2.
  xi << 0, 0, M_PI, 2, 0, 0;
  const Pose T = se3_exp(xi);
  EXPECT_NEAR(T.translation().x(), 0.0, 1e-12);
  EXPECT_NEAR(T.translation().y(), 4.0 / M_PI, 1e-12);
}

TEST(Se3, LogExpRoundTrip) {
  std::mt19937 rng(2);
  for (int k = 0; k < 500; ++k) {
    const Vector6d xi = random_tangent(rng, 3.0, 20.0);
    if (xi.head<3>().norm() > M_PI - 1e-3) continue;
    EXPECT_LT((se3_log(se3_exp(xi)) - xi).norm(), 1e-9);
  }
}

TEST(Se3, InterpolationEndpointsAndMidpoint) {
  const Pose a = from_xyz_rpy(1, 2, 3, 0.1, -0.2, 0.3);
  const Pose b = from_xyz_rpy(-4, 0, 1, 0.4, 0.1, -1.0);
  EXPECT_TRUE(interpolate(a, b, 0.0).isApprox(a, 1e-12));
  EXPECT_TRUE(interpolate(a, b, 1.0).isApprox(b, 1e-9));
  const Pose mid = interpolate(a, b, 0.5);
  // The midpoint is halfway along the geodesic: mid^-1 b equals a^-1 mid.
  EXPECT_TRUE((mid.inverse() * b).isApprox(a.inverse() * mid, 1e-9));
  // Pure translation interpolates linearly.
  const Pose c = from_xyz_rpy(10, 0, 0, 0, 0, 0);
  EXPECT_TRUE(
      interpolate(Pose::Identity(), c, 0.25).translation().isApprox(Eigen::Vector3d(2.5, 0, 0)));
}

TEST(Se3, MatrixKittiQuaternionRoundTrips) {
  const Pose T = from_xyz_rpy(0.5, -1.5, 2.0, 0.2, 0.3, -2.5);
  EXPECT_TRUE(from_matrix(to_matrix(T)).isApprox(T, 1e-12));
  EXPECT_TRUE(from_kitti_row(to_kitti_row(T)).isApprox(T, 1e-12));
  const Eigen::Quaterniond q(T.linear());
  EXPECT_TRUE(from_translation_quaternion(T.translation(), q).isApprox(T, 1e-12));
  const auto row = to_kitti_row(T);
  EXPECT_DOUBLE_EQ(row[3], 0.5);
  EXPECT_DOUBLE_EQ(row[7], -1.5);
  EXPECT_DOUBLE_EQ(row[11], 2.0);
}

TEST(Se3, RollPitchYawConventionAndInverse) {
  // Yaw of 90 degrees maps x to y; pitch of 90 degrees maps x to -z.
  EXPECT_TRUE((from_xyz_rpy(0, 0, 0, 0, 0, M_PI / 2).linear() * Eigen::Vector3d::UnitX())
                  .isApprox(Eigen::Vector3d::UnitY(), 1e-12));
  EXPECT_TRUE((from_xyz_rpy(0, 0, 0, 0, M_PI / 2, 0).linear() * Eigen::Vector3d::UnitX())
                  .isApprox(-Eigen::Vector3d::UnitZ(), 1e-12));
  const auto v = to_xyz_rpy(from_xyz_rpy(1, 2, 3, 0.1, -0.4, 2.9));
  EXPECT_NEAR(v(3), 0.1, 1e-12);
  EXPECT_NEAR(v(4), -0.4, 1e-12);
  EXPECT_NEAR(v(5), 2.9, 1e-12);
}

TEST(Se3, FromMatrixReorthonormalisesAndValidityCheck) {
  Eigen::Matrix4d M = to_matrix(from_xyz_rpy(0, 0, 0, 0.3, 0.2, 0.1));
  EXPECT_TRUE(is_valid_pose(M));
  M(0, 0) += 1e-4;
  EXPECT_FALSE(is_valid_pose(M));
  EXPECT_TRUE(is_valid_pose(to_matrix(from_matrix(M)), 1e-9));
  M(1, 3) = std::nan("");
  EXPECT_FALSE(is_valid_pose(M));
}

TEST(Se3, AngleAndNorm) {
  EXPECT_NEAR(rotation_angle(from_xyz_rpy(3, 4, 0, 0, 0, 0.7)), 0.7, 1e-12);
  EXPECT_NEAR(translation_norm(from_xyz_rpy(3, 4, 0, 0, 0, 0.7)), 5.0, 1e-12);
}
