#include "scanmatch/registration/ctf_fine.hpp"

namespace scanmatch {
namespace {

// The planar-Gaussian residual of CtfFineFactor with the voxel of each point fixed.
struct AssociatedPlanarFactor {
  const PointCloud& source;
  const std::vector<const GaussianVoxel*>& voxels;
  std::size_t size() const { return source.size(); }
  bool linearize(const Pose& T, std::size_t i, LinearSystem& system,
                 const RobustKernel& kernel) const {
    const GaussianVoxel* v = voxels[i];
    if (!v) return false;
    const Eigen::Vector3d p = source.points[i].cast<double>();
    system.add<3>(point_jacobian(T, p), T * p - v->mean, v->planar_information, kernel);
    return true;
  }
};

}  // namespace

RegistrationResult register_ctf_fine(const PointCloud& source, const GaussianVoxelMap& map,
                                     const Pose& initial, const CtfFineOptions& options) {
  std::vector<const GaussianVoxel*> voxels(source.size(), nullptr);
  SolverOptions inner = options.solver;
  inner.max_iterations = options.gauss_newton_steps;
  inner.levenberg_marquardt = false;
  RegistrationResult result;
  result.transform = initial;
  result.stop_reason = "association limit";
  int iterations = 0;
  for (int association = 0; association < options.max_associations; ++association) {
    for (std::size_t i = 0; i < source.size(); ++i) {
      const GaussianVoxel* v = map.find(result.transform * source.points[i].cast<double>());
      voxels[i] = v && v->flatness <= options.max_flatness ? v : nullptr;
    }
    const Pose before = result.transform;
    RegistrationResult step = optimize(AssociatedPlanarFactor{source, voxels}, before, inner);
    iterations += step.iterations;
    if (step.inliers < 6) {
      result = std::move(step);
      result.transform = before;
      result.iterations = iterations;
      result.converged = false;
      return result;
    }
    result = std::move(step);
    const Pose change = before.inverse() * result.transform;
    if (rotation_angle(change) < options.tolerance &&
        change.translation().norm() < options.tolerance) {
      result.converged = true;
      result.stop_reason = "pose change below tolerance";
      break;
    }
    result.stop_reason = "association limit";
  }
  result.iterations = iterations;
  return result;
}

}  // namespace scanmatch
