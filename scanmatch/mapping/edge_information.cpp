// The information matrices of the pose graph's edges (edge_information.hpp).
#include "scanmatch/mapping/edge_information.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>

namespace scanmatch {
namespace {

// A loop edge's information from its registration's Gauss-Newton `hessian` (translation first,
// then rotation; 3x3 in 2D, 6x6 in 3D): the shape kept, scaled so that the best translation
// direction has `sigma_translation`; the rotation block's best direction capped at
// `sigma_rotation` (at that scale it claims the points' lever arm worth of certainty, more than
// submaps built from odometry poses hold); eigenvalues floored at 1e-6 of the largest so that the
// graph gets a positive definite matrix even where the geometry leaves a direction free (along a
// corridor). `fallback` where the Hessian is not usable.
template <int Dim>
typename PoseGraph<Dim>::Information shaped_loop_information(
    const typename PoseGraph<Dim>::Information& hessian, double sigma_translation,
    double sigma_rotation, const typename PoseGraph<Dim>::Information& fallback) {
  using Matrix = typename PoseGraph<Dim>::Information;
  constexpr int kDof = PoseGraph<Dim>::kDof, kRotation = kDof - Dim;
  using Vector = Eigen::Matrix<double, kDof, 1>;
  if (!hessian.allFinite()) return fallback;
  const Matrix H = 0.5 * (hessian + hessian.transpose());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, Dim, Dim>> translation(
      H.template topLeftCorner<Dim, Dim>());
  const double strongest = translation.eigenvalues()(Dim - 1);
  if (!(strongest > 0.0)) return fallback;
  Matrix scaled = H / (strongest * sigma_translation * sigma_translation);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, kRotation, kRotation>> rotation(
      scaled.template bottomRightCorner<kRotation, kRotation>());
  const double rotation_cap = 1.0 / (sigma_rotation * sigma_rotation);
  if (rotation.eigenvalues()(kRotation - 1) > rotation_cap) {
    // Rows and columns scaled alike, so the matrix stays positive semi-definite.
    Vector d = Vector::Ones();
    d.template tail<kRotation>().setConstant(
        std::sqrt(rotation_cap / rotation.eigenvalues()(kRotation - 1)));
    scaled = d.asDiagonal() * scaled * d.asDiagonal();
  }
  const Eigen::SelfAdjointEigenSolver<Matrix> eigen(scaled);
  if (eigen.info() != Eigen::Success) return fallback;
  const double floor = 1e-6 * eigen.eigenvalues().maxCoeff();
  const Vector values = eigen.eigenvalues().cwiseMax(floor);
  if (!(floor > 0.0) || !values.allFinite()) return fallback;
  const Matrix information =
      eigen.eigenvectors() * values.asDiagonal() * eigen.eigenvectors().transpose();
  return 0.5 * (information + information.transpose());
}

// The information with only `kept` (a share in [0, 1]) of what it holds along the translation
// `direction` (unit, in the residual's frame), plus a trace, 1e-6 of its largest eigenvalue, that
// keeps it positive definite when nothing is kept.
Eigen::Matrix3d weakened_along(const Eigen::Matrix3d& information, const Eigen::Vector2d& direction,
                               double kept) {
  Eigen::Vector3d u = Eigen::Vector3d::Zero();
  u.head<2>() = direction.normalized();
  const Eigen::Matrix3d keep = Eigen::Matrix3d::Identity() - u * u.transpose();
  const Eigen::Matrix3d held = keep * information * keep;
  const double largest =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(information, Eigen::EigenvaluesOnly)
          .eigenvalues()
          .maxCoeff();
  const Eigen::Matrix3d out =
      held + kept * (information - held) + 1e-6 * largest * u * u.transpose();
  return 0.5 * (out + out.transpose());
}

}  // namespace

Eigen::Matrix3d loop_information_2d(const LoopVerification2D& match, double sigma_xy,
                                    double sigma_theta, bool hessian_shaped, double sliding_kept) {
  const Eigen::Matrix3d fallback = diagonal_information<2>(sigma_xy, sigma_theta);
  // Along a corridor a loop then holds nothing, so one that slid cannot pull the map along it.
  const Eigen::Matrix3d information =
      hessian_shaped ? shaped_loop_information<2>(match.hessian, sigma_xy, sigma_theta, fallback)
                     : fallback;
  return match.sliding ? weakened_along(information, match.slide_direction, sliding_kept)
                       : information;
}

PoseGraph3D::Information loop_information_3d(const Matrix6d& hessian, double sigma_translation,
                                             double sigma_rotation) {
  return shaped_loop_information<3>(hessian, sigma_translation, sigma_rotation,
                                    diagonal_information<3>(sigma_translation, sigma_rotation));
}

Eigen::Matrix3d spread_odometry_information(const Eigen::Matrix2d& spread, const Pose2& measurement,
                                            double sigma_xy, double sigma_theta, double normal) {
  Eigen::Matrix3d information = diagonal_information<2>(sigma_xy, sigma_theta);
  if (!spread.allFinite()) return information;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(0.5 * (spread + spread.transpose()));
  const Eigen::Vector2d widened =
      (eigen.eigenvalues().array() - normal * normal).max(0.0) + sigma_xy * sigma_xy;
  if (widened.maxCoeff() <= sigma_xy * sigma_xy) return information;
  // The spread lies in the previous keyframe's frame, the edge's residual in the measured step's
  // end frame (pose_graph.hpp): turned by the step's rotation, or a 40-degree turn loosens a
  // direction 40 degrees off the open one.
  const Eigen::Matrix2d to_residual = measurement.rotation().transpose();
  information.topLeftCorner<2, 2>() = to_residual * eigen.eigenvectors() *
                                      widened.cwiseInverse().asDiagonal() *
                                      eigen.eigenvectors().transpose() * to_residual.transpose();
  return information;
}

}  // namespace scanmatch
