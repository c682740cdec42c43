#include "scanmatch/odometry/fine_stage.hpp"

#include <algorithm>
#include <cmath>

#include "scanmatch/odometry/frame_odometry.hpp"

namespace scanmatch {

FineStage::FineStage(const OdometryConfig& config) {
  options_.max_iterations = config.fine_max_iterations;
  options_.tolerance = config.fine_tolerance;
  options_.max_flatness = static_cast<float>(config.fine_max_flatness);
  options_.with_cost = false;  // the odometry reads the pose, inliers and information
  SolverOptions& solver = options_.solver;
  solver = config.registration.solver;
  reported_degeneracy_ratio_ = config.degeneracy_ratio;
  guard_ratio_ = config.degeneracy_guard_ratio;
  solver.kernel = RobustKernel{};
  if (config.fine_kernel_distance > 0.0) {
    // The residual is weighted by 1/eps along the normal: scale the kernel to match.
    solver.kernel.type = KernelType::kCauchy;
    solver.kernel.scale = config.fine_kernel_distance / std::sqrt(config.registration.ctf_epsilon);
  }
}

FineResult FineStage::refine(const PointCloud& frame, const GaussianVoxelMap& map,
                             const Pose& start, bool young_map) const {
  CtfFineOptions options = options_;
  options.solver.degeneracy_ratio = young_map ? reported_degeneracy_ratio_ : guard_ratio_;
  // Rotations count as the displacement they cause at the frame's own RMS range: a fixed lever
  // would call a narrow corridor's well-constrained roll degenerate.
  double sum_r2 = 0.0;
  for (const Point& p : frame.points) sum_r2 += p.squaredNorm();
  options.solver.degeneracy_range =
      std::max(std::sqrt(sum_r2 / static_cast<double>(frame.size())), 0.1);
  const RegistrationResult fine = register_ctf_fine(frame, map, start, options);
  FineResult result;
  result.pose = start;
  result.iterations = fine.iterations;
  result.paired = fine.inliers;
  result.condition_number = fine.condition_number;
  result.registered = fine.inliers >= kMinimumFramePoints;
  if (result.registered) {
    result.pose = fine.transform;
    result.degenerate_directions =
        analyse_degeneracy(fine.information, options.solver.degeneracy_range,
                           reported_degeneracy_ratio_)
            .directions;
  }
  return result;
}

}  // namespace scanmatch
