#include "scanmatch/geometry/beam_elevation.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "scanmatch/geometry/kdtree.hpp"

namespace scanmatch {
namespace {

constexpr std::size_t kNeighbours = 8;
constexpr float kMaxNeighbourSquared = 1.5f * 1.5f;  // m^2: a plane's farthest neighbour
constexpr float kMaxPairSquared = 1.0f;              // m^2: a source point's nearest target point
constexpr double kMaxFlatness = 0.1;                 // smallest over middle eigenvalue
// m^2, the middle eigenvalue: the neighbours must spread across the plane. One beam's ring alone
// is a line whose fitted "normal" lies in the beam's vertical plane, the very direction the bias
// moves points, and its residuals would pull the bias (campus-os1: -0.2 deg instead of 0 without).
constexpr double kMinSpread = 0.003;
constexpr double kKernel = 0.1;  // m: Cauchy kernel of the plane distances
// Pairs are found kRounds times (from the odometry's pose, then from the solution), and each set
// is solved by kIterationsPerRound Gauss-Newton steps.
constexpr int kRounds = 2, kIterationsPerRound = 4;
constexpr std::size_t kMaxSourcePoints = 4000;

// d ElevationTurn(a)(p) / da at a = 0.
Eigen::Vector3d turn_direction(const Eigen::Vector3d& p) {
  const double horizontal = p.head<2>().norm();
  if (!(horizontal > 0.0)) return Eigen::Vector3d::Zero();
  return {-p.z() * p.x() / horizontal, -p.z() * p.y() / horizontal, horizontal};
}

struct TargetPlane {
  enum : std::uint8_t { kUnknown, kPlane, kNone } state = kUnknown;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
};

const TargetPlane& plane_of(std::size_t index, const PointCloud& target, const KdTree& tree,
                            std::vector<TargetPlane>& planes) {
  TargetPlane& plane = planes[index];
  if (plane.state != TargetPlane::kUnknown) return plane;
  plane.state = TargetPlane::kNone;
  std::array<std::size_t, kNeighbours> indices{};
  std::array<float, kNeighbours> squared{};
  const std::size_t found =
      tree.knn(target.points[index], kNeighbours, indices.data(), squared.data());
  if (found < kNeighbours || squared[found - 1] > kMaxNeighbourSquared) return plane;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < found; ++k) mean += target.points[indices[k]].cast<double>();
  mean /= static_cast<double>(found);
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (std::size_t k = 0; k < found; ++k) {
    const Eigen::Vector3d d = target.points[indices[k]].cast<double>() - mean;
    covariance += d * d.transpose();
  }
  covariance /= static_cast<double>(found);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(covariance);
  const Eigen::Vector3d values = eigen.eigenvalues();  // ascending
  if (values(1) < kMinSpread || values(0) > kMaxFlatness * values(1)) return plane;
  plane.state = TargetPlane::kPlane;
  plane.normal = eigen.eigenvectors().col(0);
  return plane;
}

}  // namespace

ElevationBiasFromPair estimate_elevation_bias(const PointCloud& target, const PointCloud& source,
                                              const Pose& source_in_target) {
  ElevationBiasFromPair result;
  if (target.size() < kNeighbours || source.empty()) return result;
  const KdTree tree(target.points);
  std::vector<TargetPlane> planes(target.size());
  const std::size_t stride = std::max<std::size_t>(1, source.size() / kMaxSourcePoints);

  using Matrix7d = Eigen::Matrix<double, 7, 7>;
  using Vector7d = Eigen::Matrix<double, 7, 1>;
  struct Pair {
    Eigen::Vector3d source, target, normal, source_turn, target_turn;
  };
  std::vector<Pair> pairs;
  Eigen::Matrix3d rotation = source_in_target.linear();
  Eigen::Vector3d translation = source_in_target.translation();
  double bias = 0.0;
  Matrix7d information = Matrix7d::Zero();
  double weighted_squares = 0.0, weights = 0.0;
  for (int round = 0; round < kRounds; ++round) {
    // Pairs from the current pose and bias: both frames corrected (points turned down by the
    // bias). The tree holds the target as delivered, so a corrected query is turned back up.
    const ElevationTurn correct(-bias), uncorrect(bias);
    pairs.clear();
    for (std::size_t i = 0; i < source.size(); i += stride) {
      const Eigen::Vector3d b = source.points[i].cast<double>();
      if (!b.allFinite()) continue;
      const Eigen::Vector3d q = rotation * correct(b) + translation;
      std::size_t index = 0;
      float squared = 0.0f;
      if (!tree.nearest(uncorrect(q).cast<float>(), kMaxPairSquared, index, squared)) continue;
      const TargetPlane& plane = plane_of(index, target, tree, planes);
      if (plane.state != TargetPlane::kPlane) continue;
      const Eigen::Vector3d a = target.points[index].cast<double>();
      pairs.push_back({b, a, plane.normal, turn_direction(b), turn_direction(a)});
    }
    result.planes = pairs.size();
    if (pairs.size() < 7) return ElevationBiasFromPair{};
    for (int iteration = 0; iteration < kIterationsPerRound; ++iteration) {
      const ElevationTurn turn_down(-bias);
      information.setZero();
      Vector7d gradient = Vector7d::Zero();
      weighted_squares = weights = 0.0;
      for (const Pair& pair : pairs) {
        const Eigen::Vector3d q = rotation * turn_down(pair.source) + translation;
        const Eigen::Vector3d& n = pair.normal;
        const double residual = n.dot(q - turn_down(pair.target));
        Vector7d jacobian;
        jacobian.head<3>() = n;
        jacobian.segment<3>(3) = q.cross(n);
        jacobian(6) = n.dot(pair.target_turn - rotation * pair.source_turn);
        const double weight = 1.0 / (1.0 + (residual / kKernel) * (residual / kKernel));
        information.noalias() += weight * jacobian * jacobian.transpose();
        gradient.noalias() += weight * residual * jacobian;
        weighted_squares += weight * residual * residual;
        weights += weight;
      }
      const Eigen::LDLT<Matrix7d> solver(information);
      if (solver.info() != Eigen::Success) return ElevationBiasFromPair{};
      const Vector7d step = -solver.solve(gradient);
      if (!step.allFinite()) return ElevationBiasFromPair{};
      // Left-multiplied update of the pose (translation first, rotation after), then the bias.
      const Eigen::Matrix3d turn = so3_exp(step.segment<3>(3));
      rotation = turn * rotation;
      translation = turn * translation + step.head<3>();
      bias += step(6);
      if (step.norm() < 1e-7) break;
    }
  }
  // The bias's information with the pose's directions eliminated (Schur complement), at the
  // residuals' own scale.
  const Eigen::Matrix<double, 6, 6> pose_information = information.topLeftCorner<6, 6>();
  const Eigen::Matrix<double, 6, 1> coupling = information.block<6, 1>(0, 6);
  const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> pose_solver(pose_information);
  const double marginal = information(6, 6) - coupling.dot(pose_solver.solve(coupling));
  const double variance = weighted_squares / std::max(weights, 1.0);
  if (!(marginal > 0.0) || !(variance > 0.0) || !std::isfinite(bias))
    return ElevationBiasFromPair{};
  result.bias = bias;
  result.standard_error = std::sqrt(variance / marginal);
  return result;
}

}  // namespace scanmatch
