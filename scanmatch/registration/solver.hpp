#pragma once
// The one Gauss-Newton / Levenberg-Marquardt solver on SE(3) that every registration method uses.
//
// Perturbation: right (body frame), T <- T * exp(delta), delta = [rotation; translation], the
// tangent order of core/se3.hpp. For a transformed point T p the Jacobian is [-R [p]x, R].
//
// A method is a Factor: an object with
//   std::size_t size() const;                                  // number of source elements
//   bool linearize(const Pose& T, std::size_t i, LinearSystem& system, const RobustKernel& kernel)
//   const;
// which finds element i's correspondence under T and adds its residual through
// LinearSystem::add (returning false when it has none). A factor on a hot path may instead
// provide
//   void linearize_range(const Pose& T, std::size_t begin, std::size_t end, LinearSystem& system,
//                        const RobustKernel& kernel) const;
// for elements [begin, end), accumulating in its own form first (see SensorCentredSystem).
// The solver owns everything else.

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <functional>
#include <string>

#include "scanmatch/core/se3.hpp"

namespace scanmatch {

enum class KernelType { kNone, kHuber, kCauchy, kTukey, kGemanMcClure };
/// "none", "huber", "cauchy", "tukey", "geman-mcclure"; throws Error.
KernelType parse_kernel(const std::string& name);
/// The inverse of parse_kernel.
const char* kernel_name(KernelType type);

/// Robust kernel on the squared (Mahalanobis) residual s = r^T W r, as an IRLS weight.
struct RobustKernel {
  KernelType type = KernelType::kNone;
  double scale = 1.0;  ///< residual size (m) where the kernel starts to down-weight

  double weight(double s) const {
    const double c2 = scale * scale;
    switch (type) {
      case KernelType::kNone:
        return 1.0;
      case KernelType::kHuber:
        return s <= c2 ? 1.0 : scale / std::sqrt(s);
      case KernelType::kCauchy:
        return 1.0 / (1.0 + s / c2);
      case KernelType::kTukey: {
        if (s >= c2) return 0.0;
        const double u = 1.0 - s / c2;
        return u * u;
      }
      case KernelType::kGemanMcClure: {
        const double d = c2 + s;
        return c2 * c2 / (d * d);
      }
    }
    return 1.0;
  }
  /// The robust cost rho(s) whose IRLS weight is weight(s) (rho(s) ~ s for small s).
  double cost(double s) const {
    const double c2 = scale * scale;
    switch (type) {
      case KernelType::kNone:
        return s;
      case KernelType::kHuber:
        return s <= c2 ? s : 2.0 * scale * std::sqrt(s) - c2;
      case KernelType::kCauchy:
        return c2 * std::log1p(s / c2);
      case KernelType::kTukey: {
        if (s >= c2) return c2 / 3.0;
        const double u = 1.0 - s / c2;
        return c2 / 3.0 * (1.0 - u * u * u);
      }
      case KernelType::kGemanMcClure:
        return c2 * s / (c2 + s);
    }
    return s;
  }
};

/// Normal equations H delta = -b accumulated over correspondences.
struct LinearSystem {
  Matrix6d H = Matrix6d::Zero();
  Vector6d b = Vector6d::Zero();
  double cost = 0.0;
  std::size_t inliers = 0;
  double squared_error = 0.0;  ///< sum of plain squared residual norms (for fitness)

  /// Adds residual r (D rows) with Jacobian J (D x 6) and information W (D x D).
  template <int D>
  void add(const Eigen::Matrix<double, D, 6>& J, const Eigen::Matrix<double, D, 1>& r,
           const Eigen::Matrix<double, D, D>& W, const RobustKernel& kernel) {
    const double s = r.dot(W * r);
    const double w = kernel.weight(s);
    const Eigen::Matrix<double, 6, D> JtW = J.transpose() * (w * W);
    H.noalias() += JtW * J;
    b.noalias() += JtW * r;
    cost += kernel.cost(s);
    squared_error += r.squaredNorm();
    ++inliers;
  }
  /// Weighted form for methods that compute their own weight (NDT's score).
  template <int D>
  void add_weighted(const Eigen::Matrix<double, D, 6>& J, const Eigen::Matrix<double, D, 1>& r,
                    const Eigen::Matrix<double, D, D>& W, double weight, double cost_term) {
    const Eigen::Matrix<double, 6, D> JtW = J.transpose() * (weight * W);
    H.noalias() += JtW * J;
    b.noalias() += JtW * r;
    cost += cost_term;
    squared_error += r.squaredNorm();
    ++inliers;
  }
  void operator+=(const LinearSystem& o) {
    H += o.H;
    b += o.b;
    cost += o.cost;
    inliers += o.inliers;
    squared_error += o.squared_error;
  }
};

/// Jacobian of T p with respect to the right perturbation (tangent order [rotation; translation]).
inline Eigen::Matrix<double, 3, 6> point_jacobian(const Pose& T, const Eigen::Vector3d& p) {
  Eigen::Matrix<double, 3, 6> J;
  J.leftCols<3>() = -T.linear() * skew(p);
  J.rightCols<3>() = T.linear();
  return J;
}

/// Normal equations in the sensor-centred, world-aligned perturbation x' = x + w x y + v, where
/// y = R p is the point rotated but not translated. There the Jacobian of a point is
/// [-[y]x, I], whose products reduce to cross products and a few sums; add_to() turns them into
/// the solver's body perturbation (T exp(delta): delta = diag(R^T, R^T) [w; v], exactly).
struct SensorCentredSystem {
  Matrix6d H = Matrix6d::Zero();
  Vector6d b = Vector6d::Zero();
  double cost = 0.0, squared_error = 0.0;
  std::size_t inliers = 0;
  void add_to(LinearSystem& system, const Eigen::Matrix3d& R) const {
    Matrix6d H_body;
    const Eigen::Matrix3d Rt = R.transpose();
    H_body.topLeftCorner<3, 3>().noalias() = Rt * H.topLeftCorner<3, 3>() * R;
    H_body.topRightCorner<3, 3>().noalias() = Rt * H.topRightCorner<3, 3>() * R;
    H_body.bottomLeftCorner<3, 3>() = H_body.topRightCorner<3, 3>().transpose();
    H_body.bottomRightCorner<3, 3>().noalias() = Rt * H.bottomRightCorner<3, 3>() * R;
    system.H += H_body;
    system.b.head<3>() += Rt * b.head<3>();
    system.b.tail<3>() += Rt * b.tail<3>();
    system.cost += cost;
    system.squared_error += squared_error;
    system.inliers += inliers;
  }
};

struct SolverOptions {
  int max_iterations = 30;
  double rotation_tolerance = 1e-5;     ///< rad: converged when the update is smaller ...
  double translation_tolerance = 1e-5;  ///< m: ... in both rotation and translation,
  double relative_cost_tolerance =
      1e-9;                          ///< or the cost changes relatively less than this (0: off)
  bool levenberg_marquardt = false;  ///< LM damping (accepts only cost-decreasing steps)
  double initial_lambda = 1e-6;
  RobustKernel kernel;
  int num_threads = 1;  ///< 1: single-threaded reduction; > 1: TBB with that many threads
  /// Degeneracy guard (Zhang et al.'s solution remapping): directions of the information matrix
  /// whose eigenvalue is below this fraction of the largest get no update, so they keep the
  /// initial guess. 0 turns it off. See analyse_degeneracy for the scaling.
  double degeneracy_ratio = 0.0;
  double degeneracy_range = 10.0;  ///< m: a rotation counts as the displacement at this range
  /// Gauss-Newton only: after the last step (below tolerance, or the iteration limit) linearise
  /// once more, so that the result's cost, inliers and information are those of the returned
  /// pose. false saves that pass (one of ~5 in the odometry's fine stage); the result then
  /// reports the linearisation before the last step.
  bool final_linearization = true;
};

/// Which directions of an information matrix H (tangent order [rotation; translation]) are
/// degenerate. Rotations are scaled to displacements at `range` metres so that both kinds compare;
/// a direction is degenerate when its scaled eigenvalue is below `ratio` times the largest.
struct Degeneracy {
  int directions = 0;                              ///< number of degenerate directions
  Vector6d scaled_eigenvalues = Vector6d::Zero();  ///< ascending, divided by the largest
  /// Projects a tangent vector onto the well-constrained directions (identity when none is
  /// degenerate).
  Matrix6d projector = Matrix6d::Identity();
};
Degeneracy analyse_degeneracy(const Matrix6d& H, double range, double ratio);

struct RegistrationResult {
  Pose transform = Pose::Identity();  ///< maps source coordinates into the target frame
  int iterations = 0;
  double cost = 0.0;  ///< final robust cost
  std::size_t inliers = 0;
  double fitness = 0.0;  ///< mean squared residual norm of the inliers, m^2
  bool converged = false;
  std::string stop_reason;
  Matrix6d information = Matrix6d::Zero();  ///< H at the solution
  Vector6d eigenvalues = Vector6d::Zero();  ///< of the information, ascending
  double condition_number = 0.0;            ///< largest / smallest eigenvalue (inf if singular)
  std::string summary() const;
};

/// Linearises every element at T (one thread or TBB), returning the summed system.
LinearSystem reduce_parallel(
    std::size_t n, int num_threads,
    const std::function<void(std::size_t, std::size_t, LinearSystem&)>& block);

template <typename Factor>
LinearSystem linearize_all(const Factor& factor, const Pose& T, const SolverOptions& options) {
  const auto block = [&](std::size_t begin, std::size_t end, LinearSystem& system) {
    if constexpr (requires { factor.linearize_range(T, begin, end, system, options.kernel); })
      factor.linearize_range(T, begin, end, system, options.kernel);
    else
      for (std::size_t i = begin; i < end; ++i) factor.linearize(T, i, system, options.kernel);
  };
  if (options.num_threads <= 1) {
    LinearSystem system;
    block(0, factor.size(), system);
    return system;
  }
  return reduce_parallel(factor.size(), options.num_threads, block);
}

void finish_result(RegistrationResult& result, const LinearSystem& system);

/// Minimises the factor's cost over T starting from `initial`. `stop_at(T)` is asked after every
/// accepted step; true ends the solve there (stop_reason "stopped by the caller"): a caller that
/// knows where a pose leads, such as one of several starts reaching an optimum another start
/// already found, saves the rest of the descent.
template <typename Factor, typename StopAt>
RegistrationResult optimize(const Factor& factor, const Pose& initial, const SolverOptions& options,
                            const StopAt& stop_at) {
  RegistrationResult result;
  Pose T = initial;
  double lambda = options.initial_lambda;
  LinearSystem system = linearize_all(factor, T, options);
  result.stop_reason = "iteration limit";
  for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
    result.iterations = iteration + 1;
    if (system.inliers < 6) {
      result.stop_reason = "too few correspondences (" + std::to_string(system.inliers) + ")";
      break;
    }
    Matrix6d H = system.H;
    if (options.levenberg_marquardt) H.diagonal() += lambda * (Vector6d::Ones() + H.diagonal());
    Vector6d delta = H.ldlt().solve(-system.b);
    if (options.degeneracy_ratio > 0.0)
      delta = analyse_degeneracy(system.H, options.degeneracy_range, options.degeneracy_ratio)
                  .projector *
              delta;
    if (!delta.allFinite()) {
      result.stop_reason = "singular system";
      break;
    }
    const Pose candidate = orthonormalized(T * se3_exp(delta));
    const bool small_step = delta.head<3>().norm() < options.rotation_tolerance &&
                            delta.tail<3>().norm() < options.translation_tolerance;
    if (!options.final_linearization && !options.levenberg_marquardt &&
        (small_step || iteration + 1 == options.max_iterations)) {
      T = candidate;
      if (small_step) {
        result.converged = true;
        result.stop_reason = "update below tolerance";
      }
      break;
    }
    LinearSystem next = linearize_all(factor, candidate, options);
    if (options.levenberg_marquardt && next.cost > system.cost && next.inliers >= system.inliers) {
      lambda *= 10.0;  // reject the step, damp more
      if (lambda > 1e6) {
        result.stop_reason = "no decreasing step";
        break;
      }
      continue;
    }
    if (options.levenberg_marquardt) lambda = std::max(lambda / 10.0, 1e-12);
    const double previous_cost = system.cost;
    T = candidate;
    system = std::move(next);
    if (small_step) {
      result.converged = true;
      result.stop_reason = "update below tolerance";
      break;
    }
    if (stop_at(T)) {
      result.stop_reason = "stopped by the caller";
      break;
    }
    if (options.relative_cost_tolerance > 0.0 &&
        std::abs(previous_cost - system.cost) <=
            options.relative_cost_tolerance * std::max(std::abs(previous_cost), 1e-30)) {
      result.converged = true;
      result.stop_reason = "cost change below tolerance";
      break;
    }
  }
  result.transform = T;
  finish_result(result, system);
  return result;
}

/// Minimises the factor's cost over T starting from `initial`.
template <typename Factor>
RegistrationResult optimize(const Factor& factor, const Pose& initial,
                            const SolverOptions& options) {
  return optimize(factor, initial, options, [](const Pose&) { return false; });
}

}  // namespace scanmatch
