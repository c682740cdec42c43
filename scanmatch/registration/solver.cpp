#include "scanmatch/registration/solver.hpp"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <cstdio>
#include <limits>

#include "scanmatch/core/error.hpp"
#include "scanmatch/core/parallel.hpp"

namespace scanmatch {

KernelType parse_kernel(const std::string& name) {
  if (name == "none") return KernelType::kNone;
  if (name == "huber") return KernelType::kHuber;
  if (name == "cauchy") return KernelType::kCauchy;
  if (name == "tukey") return KernelType::kTukey;
  if (name == "geman-mcclure") return KernelType::kGemanMcClure;
  throw Error("unknown robust kernel '" + name +
              "' (valid: none, huber, cauchy, tukey, geman-mcclure)");
}

const char* kernel_name(KernelType type) {
  switch (type) {
    case KernelType::kNone:
      return "none";
    case KernelType::kHuber:
      return "huber";
    case KernelType::kCauchy:
      return "cauchy";
    case KernelType::kTukey:
      return "tukey";
    case KernelType::kGemanMcClure:
      return "geman-mcclure";
  }
  return "none";
}

LinearSystem reduce_parallel(
    std::size_t n, int num_threads,
    const std::function<void(std::size_t, std::size_t, LinearSystem&)>& block) {
  tbb::enumerable_thread_specific<LinearSystem> partial;
  shared_arena(num_threads).execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 512),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        block(r.begin(), r.end(), partial.local());
                      });
  });
  LinearSystem total;
  for (const LinearSystem& s : partial) total += s;
  return total;
}

void finish_result(RegistrationResult& result, const LinearSystem& system) {
  result.cost = system.cost;
  result.inliers = system.inliers;
  result.fitness =
      system.inliers > 0 ? system.squared_error / static_cast<double>(system.inliers) : 0.0;
  result.information = system.H;
  Eigen::SelfAdjointEigenSolver<Matrix6d> solver(system.H);
  result.eigenvalues = solver.eigenvalues();
  const double smallest = result.eigenvalues(0), largest = result.eigenvalues(5);
  result.condition_number =
      smallest > 0.0 ? largest / smallest : std::numeric_limits<double>::infinity();
}

Degeneracy analyse_degeneracy(const Matrix6d& H, double range, double ratio) {
  Degeneracy result;
  Vector6d scale;  // u = D delta: rotations as displacements at `range`
  scale << range, range, range, 1.0, 1.0, 1.0;
  const Matrix6d scaled = scale.cwiseInverse().asDiagonal() * H * scale.cwiseInverse().asDiagonal();
  Eigen::SelfAdjointEigenSolver<Matrix6d> solver(scaled);
  const double largest = solver.eigenvalues()(5);
  if (!(largest > 0.0) || !std::isfinite(largest)) return result;
  result.scaled_eigenvalues = solver.eigenvalues() / largest;
  Matrix6d keep = Matrix6d::Zero();
  for (int i = 0; i < 6; ++i) {
    if (result.scaled_eigenvalues(i) < ratio) {
      ++result.directions;
      continue;
    }
    keep += solver.eigenvectors().col(i) * solver.eigenvectors().col(i).transpose();
  }
  if (result.directions > 0)
    result.projector = scale.cwiseInverse().asDiagonal() * keep * scale.asDiagonal();
  return result;
}

std::string RegistrationResult::summary() const {
  char buffer[512];
  const Vector6d xyzrpy = to_xyz_rpy(transform);
  std::snprintf(
      buffer, sizeof buffer,
      "%s after %d iterations (%s); cost %.6g over %zu correspondences, fitness %.6g m^2, "
      "condition number %.3g; translation (%.4f, %.4f, %.4f) m, roll/pitch/yaw (%.4f, %.4f, %.4f) "
      "deg",
      converged ? "converged" : "not converged", iterations, stop_reason.c_str(), cost, inliers,
      fitness, condition_number, xyzrpy(0), xyzrpy(1), xyzrpy(2), xyzrpy(3) * 180 / M_PI,
      xyzrpy(4) * 180 / M_PI, xyzrpy(5) * 180 / M_PI);
  return buffer;
}

}  // namespace scanmatch
