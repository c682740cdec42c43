#pragma once
// The information matrices of the pose graph's edges (2D and 3D): diagonals from standard
// deviations, loop edges shaped by their match's Hessian (a sliding 2D loop weakened along its
// open direction), and 2D odometry edges widened where the scans leave the step open. The pose
// graph's order: translation first, then rotation (pose_graph.hpp).

#include <Eigen/Core>

#include "scanmatch/core/scan2d.hpp"
#include "scanmatch/core/se3.hpp"
#include "scanmatch/mapping/loop_verification2d.hpp"
#include "scanmatch/mapping/pose_graph.hpp"

namespace scanmatch {

/// Standard deviations `sigma_translation` (m, each axis) and `sigma_rotation` (rad, each axis)
/// as a diagonal information.
template <int Dim>
typename PoseGraph<Dim>::Information diagonal_information(double sigma_translation,
                                                          double sigma_rotation) {
  constexpr int kDof = PoseGraph<Dim>::kDof;
  Eigen::Matrix<double, kDof, 1> d;
  d.template head<Dim>().setConstant(1.0 / (sigma_translation * sigma_translation));
  d.template tail<kDof - Dim>().setConstant(1.0 / (sigma_rotation * sigma_rotation));
  return d.asDiagonal();
}

/// A 2D loop edge's information from its verification: the Hessian's shape scaled to `sigma_xy`
/// in its best direction, the rotation capped at `sigma_theta` (with `hessian_shaped` false, or
/// no usable Hessian, the diagonal of both sigmas). A sliding match
/// (LoopVerification2D::sliding) keeps only `sliding_kept` (a share in [0, 1]) of it along its
/// open direction.
Eigen::Matrix3d loop_information_2d(const LoopVerification2D& match, double sigma_xy,
                                    double sigma_theta, bool hessian_shaped, double sliding_kept);

/// A 3D loop edge's information from its fine registration's `hessian` (translation, rotation):
/// its shape scaled so that the best translation direction has `sigma_translation`, the rotation
/// block's best direction capped at `sigma_rotation` (a submap match's lever arm of tens of
/// metres would claim more); the diagonal of both sigmas where the Hessian is not usable.
PoseGraph3D::Information loop_information_3d(const Matrix6d& hessian, double sigma_translation,
                                             double sigma_rotation);

/// The information of an odometry edge (x, y, theta in the pose graph's residual frame) whose
/// step measures `measurement` (current in the previous keyframe's frame): standard deviations
/// `sigma_xy` and `sigma_theta`, the translation widened by the part of the fitting translations'
/// `spread` (their second moment about the step, m^2, in the previous keyframe's frame:
/// CorrelativeSpread::second_moment) beyond `normal` (m) in each of its directions.
Eigen::Matrix3d spread_odometry_information(const Eigen::Matrix2d& spread, const Pose2& measurement,
                                            double sigma_xy, double sigma_theta, double normal);

}  // namespace scanmatch
