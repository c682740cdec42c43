#include "scanmatch/mapping/pose_graph.hpp"

#include <ceres/ceres.h>
#include <fmt/format.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <array>
#include <cmath>
#include <memory>

#include "scanmatch/core/error.hpp"
#include "scanmatch/core/stopwatch.hpp"

namespace scanmatch {
namespace {

constexpr const char* kSource = "pose graph";

/// a - 2 pi k in (-pi, pi]; ceil has zero derivative, so Jets keep the derivative of a.
template <class T>
T wrap_angle(const T& a) {
  using std::ceil;
  const T two_pi(2.0 * M_PI);
  return a - two_pi * ceil((a - T(M_PI)) / two_pi);
}

// The residuals (the header states them); operator() runs on doubles for the outlier test too.
struct EdgeResidual2D {
  Eigen::Vector3d measurement;  // x, y, theta
  Eigen::Matrix3d sqrt_information;

  // from, to: x, y, theta.
  template <class T>
  bool operator()(const T* from, const T* to, T* residual) const {
    using std::cos, std::sin;
    const T c = cos(from[2]), s = sin(from[2]);
    const T dx = to[0] - from[0], dy = to[1] - from[1];
    // t_rel - t_meas, with t_rel = R_from^T (t_to - t_from).
    const T ex = c * dx + s * dy - T(measurement.x());
    const T ey = -s * dx + c * dy - T(measurement.y());
    const double cm = std::cos(measurement.z()), sm = std::sin(measurement.z());
    Eigen::Matrix<T, 3, 1> error;
    error << T(cm) * ex + T(sm) * ey, T(-sm) * ex + T(cm) * ey,
        wrap_angle(to[2] - from[2] - T(measurement.z()));
    Eigen::Map<Eigen::Matrix<T, 3, 1>> whitened(residual);
    whitened = sqrt_information.cast<T>() * error;
    return true;
  }
};

struct EdgeResidual3D {
  Eigen::Vector3d measured_translation;
  Eigen::Quaterniond measured_rotation;
  Eigen::Matrix<double, 6, 6> sqrt_information;

  // t: x, y, z; q: Eigen's storage order (x, y, z, w), unit length (the manifold keeps it so).
  template <class T>
  bool operator()(const T* t_from, const T* q_from, const T* t_to, const T* q_to,
                  T* residual) const {
    using Vector3T = Eigen::Matrix<T, 3, 1>;
    const Eigen::Map<const Vector3T> tf(t_from), tt(t_to);
    const Eigen::Map<const Eigen::Quaternion<T>> qf(q_from), qt(q_to);
    const Eigen::Quaternion<T> qf_inverse = qf.conjugate();
    const Vector3T t_rel = qf_inverse * (tt - tf);
    const Eigen::Quaternion<T> q_rel = qf_inverse * qt;
    const Eigen::Quaternion<T> q_meas_inverse = measured_rotation.conjugate().cast<T>();
    Eigen::Matrix<T, 6, 1> error;
    error.template head<3>() = q_meas_inverse * (t_rel - measured_translation.cast<T>());
    error.template tail<3>() = T(2.0) * (q_meas_inverse * q_rel).vec();
    Eigen::Map<Eigen::Matrix<T, 6, 1>> whitened(residual);
    whitened = sqrt_information.cast<T>() * error;
    return true;
  }
};

// Per-dimension parameter layout: 2D nodes are one block (x, y, theta); 3D nodes are two
// blocks in one array, translation [0, 3) and quaternion [3, 7).
template <int Dim>
struct Layout;

template <>
struct Layout<2> {
  using Params = std::array<double, 3>;
  using Residual = EdgeResidual2D;
  static Params encode(const Pose2& T) {
    return {T.translation().x(), T.translation().y(), pose2_angle(T)};
  }
  static Pose2 decode(const Params& p) { return pose2(p[0], p[1], wrap_angle(p[2])); }
  static Residual residual(const PoseGraph<2>::Edge& edge, const Eigen::Matrix3d& sqrt_info) {
    return {Eigen::Vector3d(edge.measurement.translation().x(), edge.measurement.translation().y(),
                            pose2_angle(edge.measurement)),
            sqrt_info};
  }
  static Eigen::Vector3d evaluate(const Residual& r, const Params& from, const Params& to) {
    Eigen::Vector3d out;
    r(from.data(), to.data(), out.data());
    return out;
  }
};

template <>
struct Layout<3> {
  using Params = std::array<double, 7>;
  using Residual = EdgeResidual3D;
  static Params encode(const Pose& T) {
    const Eigen::Quaterniond q = Eigen::Quaterniond(T.rotation()).normalized();
    const Eigen::Vector3d& t = T.translation();
    return {t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()};
  }
  static Pose decode(const Params& p) {
    return from_translation_quaternion(Eigen::Vector3d(p[0], p[1], p[2]),
                                       Eigen::Quaterniond(p[6], p[3], p[4], p[5]));
  }
  static Residual residual(const PoseGraph<3>::Edge& edge, const Matrix6d& sqrt_info) {
    return {edge.measurement.translation(),
            Eigen::Quaterniond(edge.measurement.rotation()).normalized(), sqrt_info};
  }
  static Vector6d evaluate(const Residual& r, const Params& from, const Params& to) {
    Vector6d out;
    r(from.data(), from.data() + 3, to.data(), to.data() + 3, out.data());
    return out;
  }
};

/// Upper Cholesky factor U of the information (I = U^T U): |U e|^2 = e^T I e.
template <class Matrix>
Matrix whitening(const Matrix& information) {
  return information.llt().matrixU();
}

template <class PoseType>
bool is_rigid(const PoseType& T) {
  if (!T.matrix().allFinite()) return false;
  const typename PoseType::LinearMatrixType R = T.linear();
  const double orthonormality =
      (R.transpose() * R - PoseType::LinearMatrixType::Identity()).cwiseAbs().maxCoeff();
  return orthonormality < 1e-6 && R.determinant() > 0.0;
}

template <class Matrix>
void check_information(const Matrix& information, const std::string& where) {
  if (!information.allFinite()) fail(kSource, where, "information matrix is not finite");
  const double largest = information.cwiseAbs().maxCoeff();
  if ((information - information.transpose()).cwiseAbs().maxCoeff() > 1e-9 * largest)
    fail(kSource, where, "information matrix is not symmetric");
  const Eigen::SelfAdjointEigenSolver<Matrix> eigen(information, Eigen::EigenvaluesOnly);
  const double lo = eigen.eigenvalues().minCoeff(), hi = eigen.eigenvalues().maxCoeff();
  // Relative: a rank-deficient matrix often shows a tiny positive eigenvalue from rounding.
  if (!(hi > 0.0) || lo <= 1e-12 * hi)
    fail(kSource, where,
         fmt::format("information matrix is not positive definite (eigenvalues {:g} to {:g})", lo,
                     hi));
}

/// Levenberg-Marquardt steps taken (Ceres's iteration list also holds the initial evaluation).
int iterations(const ceres::Solver::Summary& summary) {
  return summary.num_successful_steps + summary.num_unsuccessful_steps;
}

std::unique_ptr<ceres::LossFunction> make_loss(LoopKernel kernel, double scale) {
  switch (kernel) {
    case LoopKernel::kHuber:
      return std::make_unique<ceres::HuberLoss>(scale);
    case LoopKernel::kCauchy:
      return std::make_unique<ceres::CauchyLoss>(scale);
    case LoopKernel::kNone:
      break;
  }
  return nullptr;
}

// One Levenberg-Marquardt solve of the edges not `dropped`, updating params in place (node 0
// fixed). Returns false when there is nothing to solve (no edge left).
template <int Dim>
bool solve(const PoseGraphConfig& config, const std::vector<typename PoseGraph<Dim>::Edge>& edges,
           const std::vector<bool>& dropped, std::vector<typename Layout<Dim>::Params>& params,
           ceres::Solver::Summary& summary) {
  using L = Layout<Dim>;
  constexpr int kDof = PoseGraph<Dim>::kDof;
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  const std::unique_ptr<ceres::LossFunction> loop_loss =
      make_loss(config.loop_kernel, config.loop_kernel_scale);
  const std::unique_ptr<ceres::LossFunction> odometry_loss =
      make_loss(config.odometry_kernel, config.odometry_kernel_scale);
  ceres::EigenQuaternionManifold quaternion_manifold;

  // Blocks only for nodes an edge touches: Ceres needs every block in a residual.
  std::vector<bool> added(params.size(), false);
  auto add_node = [&](std::size_t i) {
    if (added[i]) return;
    added[i] = true;
    if constexpr (Dim == 2) {
      problem.AddParameterBlock(params[i].data(), 3);
      if (i == 0) problem.SetParameterBlockConstant(params[i].data());
    } else {
      problem.AddParameterBlock(params[i].data(), 3);
      problem.AddParameterBlock(params[i].data() + 3, 4, &quaternion_manifold);
      if (i == 0) {
        problem.SetParameterBlockConstant(params[i].data());
        problem.SetParameterBlockConstant(params[i].data() + 3);
      }
    }
  };
  for (std::size_t i = 0; i < edges.size(); ++i) {
    if (dropped[i]) continue;
    const auto& edge = edges[i];
    add_node(edge.from);
    add_node(edge.to);
    ceres::LossFunction* loss =
        edge.kind == EdgeKind::kLoop ? loop_loss.get() : odometry_loss.get();
    const auto residual = L::residual(edge, whitening(edge.information));
    double* from = params[edge.from].data();
    double* to = params[edge.to].data();
    if constexpr (Dim == 2) {
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<EdgeResidual2D, kDof, 3, 3>(new EdgeResidual2D(residual)),
          loss, from, to);
    } else {
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<EdgeResidual3D, kDof, 3, 4, 3, 4>(
                                   new EdgeResidual3D(residual)),
                               loss, from, from + 3, to, to + 3);
    }
  }
  if (problem.NumResidualBlocks() == 0) return false;

  ceres::Solver::Options options;
  options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  // Without a sparse Cholesky library (Debian's Ceres has SuiteSparse), conjugate gradients on
  // the normal equations need none.
  if (!ceres::IsSparseLinearAlgebraLibraryTypeAvailable(options.sparse_linear_algebra_library_type))
    options.linear_solver_type = ceres::CGNR;
  options.max_num_iterations = config.max_iterations;
  options.num_threads = config.threads;
  options.logging_type = ceres::SILENT;
  ceres::Solve(options, &problem, &summary);
  return true;
}

}  // namespace

template <int Dim>
std::size_t PoseGraph<Dim>::add_node(const PoseType& initial_pose) {
  if (!is_rigid(initial_pose))
    fail(kSource, fmt::format("node {}", poses_.size()),
         "initial pose is not finite or its rotation is not orthonormal");
  poses_.push_back(initial_pose);
  return poses_.size() - 1;
}

template <int Dim>
std::size_t PoseGraph<Dim>::add_edge(std::size_t from, std::size_t to, const PoseType& measurement,
                                     const Information& information, EdgeKind kind) {
  const std::string where = fmt::format("edge {} ({} -> {})", edges_.size(), from, to);
  for (const std::size_t node : {from, to})
    if (node >= poses_.size())
      fail(kSource, where,
           fmt::format("node {} does not exist (the graph has {} nodes)", node, poses_.size()));
  if (from == to) fail(kSource, where, "an edge must join two different nodes");
  if (!is_rigid(measurement))
    fail(kSource, where, "measurement is not finite or its rotation is not orthonormal");
  check_information(information, where);
  edges_.push_back({from, to, measurement, information, kind});
  return edges_.size() - 1;
}

template <int Dim>
typename PoseGraph<Dim>::Residual PoseGraph<Dim>::whitened_residual(std::size_t edge) const {
  using L = Layout<Dim>;
  const Edge& e = edges_.at(edge);
  return L::evaluate(L::residual(e, whitening(e.information)), L::encode(poses_[e.from]),
                     L::encode(poses_[e.to]));
}

template <int Dim>
PoseGraphSummary PoseGraph<Dim>::optimize() {
  using L = Layout<Dim>;
  const Stopwatch watch;
  PoseGraphSummary result;
  std::vector<typename L::Params> initial;
  initial.reserve(poses_.size());
  for (const PoseType& T : poses_) initial.push_back(L::encode(T));

  std::vector<typename L::Params> params = initial;
  ceres::Solver::Summary summary;
  std::vector<bool> dropped(edges_.size(), false);
  if (!solve<Dim>(config_, edges_, dropped, params, summary)) {
    result.converged = true;
    result.solve_ms = watch.ms();
    return result;
  }
  result.solves = 1;
  result.iterations = iterations(summary);
  result.initial_cost = summary.initial_cost;

  // The chi-square of each loop at the solution, unweighted by the kernel.
  const double threshold = Dim == 2 ? config_.outlier_chi2_2d : config_.outlier_chi2_3d;
  for (std::size_t i = 0; i < edges_.size(); ++i) {
    const Edge& e = edges_[i];
    if (e.kind != EdgeKind::kLoop) continue;
    const auto residual =
        L::evaluate(L::residual(e, whitening(e.information)), params[e.from], params[e.to]);
    if (residual.squaredNorm() > threshold) result.outlier_edges.push_back(i);
  }

  if (config_.drop_outliers && !result.outlier_edges.empty()) {
    for (const std::size_t i : result.outlier_edges) dropped[i] = true;
    // From the same start, so that the outliers' pull in the first solve leaves no trace.
    params = initial;
    summary = ceres::Solver::Summary();
    if (solve<Dim>(config_, edges_, dropped, params, summary)) {
      result.solves = 2;
      result.iterations += iterations(summary);
    } else {
      summary.termination_type = ceres::CONVERGENCE;  // nothing left to solve
      summary.final_cost = 0.0;
      params = initial;
    }
  }

  result.final_cost = summary.final_cost;
  result.converged = summary.termination_type == ceres::CONVERGENCE;
  if (summary.IsSolutionUsable())
    for (std::size_t i = 0; i < poses_.size(); ++i) poses_[i] = L::decode(params[i]);
  result.solve_ms = watch.ms();
  return result;
}

template class PoseGraph<2>;
template class PoseGraph<3>;

}  // namespace scanmatch
