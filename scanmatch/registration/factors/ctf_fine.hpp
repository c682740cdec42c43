#pragma once
// The CTF-ICP fine stage (docs/methods.md section 1 step 3): r = T p - mu of the map voxel
// containing T p, information Q diag(1/eps, 1, 1) Q^T (covariance eigenvalues normalised to (1, 1,
// eps)). `register --method ctf-fine` and the odometry's fine stage both run register_ctf_fine.

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/geometry/gaussian_voxel_map.hpp"
#include "scanmatch/registration/solver.hpp"

namespace scanmatch {

/// That information is exactly I + (1/eps - 1) n n^T with n the voxel normal, which lets the
/// normal equations be formed from a 6-vector instead of 6x3 products (the odometry's hot loop).
struct CtfFineFactor {
  const PointCloud& source;
  const GaussianVoxelMap& map;
  int neighbours;
  /// Voxels whose flatness (smallest / middle eigenvalue) exceeds this are not planes (corners,
  /// foliage) and are skipped; 1 keeps every voxel, as the paper does.
  float max_flatness = 1.0f;
  std::size_t size() const { return source.size(); }
  bool linearize(const Pose& T, std::size_t i, LinearSystem& system,
                 const RobustKernel& kernel) const {
    const Eigen::Vector3d p = source.points[i].cast<double>(), x = T * p;
    const double stiffness = 1.0 / map.options().planar_epsilon - 1.0;
    const Eigen::Matrix3d& R = T.linear();
    bool any = false;
    map.for_each_neighbour(x, neighbours, [&](const GaussianVoxel& v) {
      if (v.flatness > max_flatness) return;
      const Eigen::Vector3d r = x - v.mean;
      const double along_normal = v.normal.dot(r);
      const double s = r.squaredNorm() + stiffness * along_normal * along_normal;
      const double w = kernel.weight(s);
      // J^T u = [p x (R^T u); R^T u] for J = [-R [p]x, R].
      const Eigen::Vector3d Rn = R.transpose() * v.normal, Rr = R.transpose() * r;
      Vector6d g, Jr;
      g << p.cross(Rn), Rn;
      Jr << p.cross(Rr), Rr;
      // J^T J = [[|p|^2 I - p p^T, [p]x], [-[p]x, I]].
      Matrix6d JtJ;
      const Eigen::Matrix3d px = skew(p);
      JtJ.topLeftCorner<3, 3>() = p.squaredNorm() * Eigen::Matrix3d::Identity() - p * p.transpose();
      JtJ.topRightCorner<3, 3>() = px;
      JtJ.bottomLeftCorner<3, 3>() = -px;
      JtJ.bottomRightCorner<3, 3>().setIdentity();
      system.H.noalias() += w * (JtJ + stiffness * g * g.transpose());
      system.b.noalias() += w * (Jr + stiffness * along_normal * g);
      system.cost += kernel.cost(s);
      system.squared_error += r.squaredNorm();
      ++system.inliers;
      any = true;
    });
    return any;
  }
};

struct CtfFineOptions {
  int max_iterations = 10;    ///< Gauss-Newton steps (each re-pairs every point)
  double tolerance = 1e-5;    ///< m and rad: converged when a step is smaller in both
  int neighbours = 1;         ///< voxels per point: 1 (the paper), 7 or 27
  float max_flatness = 1.0f;  ///< skip voxels less planar than this (1: all, as the paper)
  SolverOptions solver;       ///< kernel, threads and degeneracy guard (its iteration limits,
                              ///< tolerances and LM switch are replaced by the fields above)
};

/// Registers `source` (sensor frame) onto the map from `initial` by plain Gauss-Newton, not
/// Levenberg-Marquardt: with one voxel per point the cost jumps where a point changes voxel, and
/// a solver that only accepts cost-decreasing steps sticks near its initial guess. For the same
/// reason it stops on the step size only. The result's information matrix and condition number
/// are those of the last linearisation (before the last step).
inline RegistrationResult register_ctf_fine(const PointCloud& source, const GaussianVoxelMap& map,
                                            const Pose& initial, const CtfFineOptions& options) {
  SolverOptions solver = options.solver;
  solver.max_iterations = options.max_iterations;
  solver.rotation_tolerance = solver.translation_tolerance = options.tolerance;
  solver.relative_cost_tolerance = 0.0;
  solver.levenberg_marquardt = false;
  solver.final_linearization = false;
  return optimize(CtfFineFactor{source, map, options.neighbours, options.max_flatness}, initial,
                  solver);
}

}  // namespace scanmatch
