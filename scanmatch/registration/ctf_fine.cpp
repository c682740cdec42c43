#include "scanmatch/registration/ctf_fine.hpp"

#include "scanmatch/registration/factors.hpp"

namespace scanmatch {

RegistrationResult register_ctf_fine(const PointCloud& source, const GaussianVoxelMap& map,
                                     const Pose& initial, const CtfFineOptions& options) {
  const CtfFineFactor factor{source, map, 1, options.max_flatness};
  const SolverOptions& solver = options.solver;
  RegistrationResult result;
  result.stop_reason = "iteration limit";
  Pose T = initial;
  LinearSystem system;
  for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
    system = linearize_all(factor, T, solver);
    result.iterations = iteration + 1;
    if (system.inliers < 6) {
      result.stop_reason = "too few correspondences (" + std::to_string(system.inliers) + ")";
      break;
    }
    Vector6d delta = system.H.ldlt().solve(-system.b);
    if (solver.degeneracy_ratio > 0.0)
      delta =
          analyse_degeneracy(system.H, solver.degeneracy_range, solver.degeneracy_ratio).projector *
          delta;
    if (!delta.allFinite()) {
      result.stop_reason = "singular system";
      break;
    }
    T = orthonormalized(T * se3_exp(delta));
    if (delta.head<3>().norm() < options.tolerance && delta.tail<3>().norm() < options.tolerance) {
      result.converged = true;
      result.stop_reason = "update below tolerance";
      break;
    }
  }
  result.transform = T;
  finish_result(result, system);
  return result;
}

}  // namespace scanmatch
