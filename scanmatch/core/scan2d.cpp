#include "scanmatch/core/scan2d.hpp"

#include <cmath>

namespace scanmatch {

Pose2 pose2(double x, double y, double theta) {
  Pose2 T = Pose2::Identity();
  T.linear() = Eigen::Rotation2Dd(theta).toRotationMatrix();
  T.translation() = Eigen::Vector2d(x, y);
  return T;
}

Pose2 pose2(const Eigen::Vector3d& xytheta) {
  return pose2(xytheta.x(), xytheta.y(), xytheta.z());
}

double pose2_angle(const Pose2& T) {
  return std::atan2(T.linear()(1, 0), T.linear()(0, 0));
}

Pose2 planar_pose(const Pose& T) {
  return pose2(T.translation().x(), T.translation().y(),
               std::atan2(T.linear()(1, 0), T.linear()(0, 0)));
}

}  // namespace scanmatch
