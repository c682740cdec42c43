#include "scanmatch/registration/planar/point_to_line.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>

#include "scanmatch/core/error.hpp"

namespace scanmatch {
namespace {

using Vec2 = Eigen::Vector2d;

/// Adds one point-to-line pair to the normal equations of the unknowns x = (tx, ty, c, s): the
/// residual is n . (M x - q) with M = [1 0 px -py; 0 1 py px].
void add_line_pair(const Vec2& p, const Vec2& on_line, const Vec2& normal, Eigen::Matrix4d& H,
                   Eigen::Vector4d& g) {
  Eigen::Matrix<double, 2, 4> M;
  M << 1, 0, p.x(), -p.y(), 0, 1, p.y(), p.x();
  const Eigen::Matrix<double, 1, 4> a = normal.transpose() * M;
  H += a.transpose() * a;
  g += a.transpose() * normal.dot(on_line);
}

Pose2 solve_line_normal_equations(const Eigen::Matrix4d& H, const Eigen::Vector4d& g) {
  // Eliminate t: for fixed v = (c, s), t = A^-1 (g_t - B v); the cost in v is v'Sv - 2h'v + k.
  const Eigen::Matrix2d A = H.topLeftCorner<2, 2>(), B = H.topRightCorner<2, 2>(),
                        D = H.bottomRightCorner<2, 2>();
  const Eigen::Vector2d gt = g.head<2>(), gv = g.tail<2>();
  if (std::abs(A.determinant()) < 1e-12)
    throw Error("point-to-line step: translation is unconstrained");
  const Eigen::Matrix2d Ainv = A.inverse();
  const Eigen::Matrix2d S = D - B.transpose() * Ainv * B;
  const Eigen::Vector2d h = gv - B.transpose() * Ainv * gt;
  // Minimise v'Sv - 2h'v subject to |v| = 1: (S + l I) v = h with |v| = 1, i.e.
  // |adj(S + l I) h|^2 = det(S + l I)^2, a quartic in l.
  const double a = S(0, 0), b = S(0, 1), d = S(1, 1);
  // adj(S + l I) h = (p0 + l h0, p1 + l h1) with p = adj(S) h.
  const double p0 = d * h.x() - b * h.y(), p1 = a * h.y() - b * h.x();
  // det(S + l I) = l^2 + (a + d) l + (a d - b^2).
  const double c1 = a + d, c0 = a * d - b * b;
  // det^2 - |adj h|^2 = 0, coefficients from l^4 down to l^0.
  Eigen::Matrix<double, 5, 1> poly;
  poly << 1.0, 2 * c1, c1 * c1 + 2 * c0 - h.squaredNorm(),
      2 * c1 * c0 - 2 * (p0 * h.x() + p1 * h.y()), c0 * c0 - p0 * p0 - p1 * p1;
  Eigen::Matrix4d companion = Eigen::Matrix4d::Zero();
  for (int k = 0; k < 4; ++k) companion(0, k) = -poly(k + 1) / poly(0);
  companion.bottomLeftCorner<3, 3>() = Eigen::Matrix3d::Identity();
  const Eigen::EigenSolver<Eigen::Matrix4d> roots(companion, false);
  Vec2 best_v(1, 0);
  double best_cost = std::numeric_limits<double>::infinity();
  const auto consider = [&](Vec2 v) {
    if (!v.allFinite() || v.norm() < 1e-12) return;
    v.normalize();
    const double cost = v.dot(S * v) - 2 * h.dot(v);
    if (cost < best_cost) {
      best_cost = cost;
      best_v = v;
    }
  };
  for (int k = 0; k < 4; ++k) {
    const std::complex<double> lambda = roots.eigenvalues()(k);
    if (std::abs(lambda.imag()) > 1e-6 * std::max(1.0, std::abs(lambda.real()))) continue;
    const Eigen::Matrix2d K = S + lambda.real() * Eigen::Matrix2d::Identity();
    if (std::abs(K.determinant()) < 1e-15) continue;
    consider(K.inverse() * h);
  }
  // Should rounding lose every real root, the unconstrained direction still gives a rotation.
  consider(h);
  Pose2 T = Pose2::Identity();
  T.linear() << best_v.x(), -best_v.y(), best_v.y(), best_v.x();
  T.translation() = Ainv * (gt - B * best_v);
  return T;
}

}  // namespace

Pose2 solve_point_to_line(const std::vector<Vec2>& points, const std::vector<Vec2>& line_points,
                          const std::vector<Vec2>& normals) {
  if (points.size() < 3 || line_points.size() != points.size() || normals.size() != points.size())
    throw Error("point-to-line step: needs three or more pairs with a normal each");
  Eigen::Matrix4d H = Eigen::Matrix4d::Zero();
  Eigen::Vector4d g = Eigen::Vector4d::Zero();
  for (std::size_t i = 0; i < points.size(); ++i)
    add_line_pair(points[i], line_points[i], normals[i], H, g);
  return solve_line_normal_equations(H, g);
}

namespace planar {

void keep_nearest_fraction(std::vector<LinePair>& pairs, double fraction) {
  const std::size_t keep = std::max<std::size_t>(
      3, static_cast<std::size_t>(std::ceil(fraction * static_cast<double>(pairs.size()))));
  if (keep >= pairs.size()) return;
  std::nth_element(pairs.begin(), pairs.begin() + static_cast<std::ptrdiff_t>(keep), pairs.end(),
                   [](const LinePair& a, const LinePair& b) { return a.distance < b.distance; });
  pairs.resize(keep);
}

Pose2 solve_line_pairs(const std::vector<LinePair>& pairs, const Pose2& current,
                       double& mean_distance) {
  Eigen::Matrix4d H = Eigen::Matrix4d::Zero();
  Eigen::Vector4d g = Eigen::Vector4d::Zero();
  double sum = 0.0;
  for (const LinePair& pair : pairs) {
    add_line_pair(pair.point, pair.on_line, pair.normal, H, g);
    sum += pair.distance;
  }
  mean_distance = sum / static_cast<double>(pairs.size());
  const double pull = 1e-6 * static_cast<double>(pairs.size());
  const Eigen::Vector4d x(current.translation().x(), current.translation().y(),
                          current.linear()(0, 0), current.linear()(1, 0));
  H.diagonal().array() += pull;
  g += pull * x;
  return solve_line_normal_equations(H, g);
}

}  // namespace planar
}  // namespace scanmatch
