#pragma once
// The CTF-ICP fine stage (docs/methods.md section 1 step 3): r = T p - mu of the map voxel
// containing T p, information Q diag(1/eps, 1, 1) Q^T (covariance eigenvalues normalised to (1, 1,
// eps)). `register --method ctf-fine` and the odometry's fine stage both run register_ctf_fine.

#include <vector>

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/geometry/gaussian_voxel_map.hpp"
#include "scanmatch/registration/solver.hpp"

namespace scanmatch {

/// That information is exactly I + k n n^T (k = 1/eps - 1, n the voxel normal), so the normal
/// equations of the points are sums of a few moments of y = R p plus the outer products of the
/// 6-vector g = [y x n; n] (SensorCentredSystem): the odometry's hot loop.
struct CtfFineFactor {
  const PointCloud& source;
  const GaussianVoxelMap& map;
  int neighbours;
  /// Voxels whose flatness (smallest / middle eigenvalue) exceeds this are not planes (corners,
  /// foliage) and are skipped; 1 keeps every voxel, as the paper does.
  float max_flatness = 1.0f;
  /// false: the system's cost stays 0 (it costs a logarithm per point with the Cauchy kernel,
  /// and plain Gauss-Newton stopping on the step size never reads it).
  bool with_cost = true;
  /// One per source point (neighbours = 1 only), or empty: remembers each point's voxel between
  /// iterations. Ranges of points are disjoint, so threads write disjoint hints.
  mutable std::vector<VoxelHint> hints = {};
  std::size_t size() const { return source.size(); }
  void linearize_range(const Pose& T, std::size_t begin, std::size_t end, LinearSystem& system,
                       const RobustKernel& kernel) const {
    const double stiffness = 1.0 / map.options().planar_epsilon - 1.0;
    const Eigen::Matrix3d& R = T.linear();
    const Eigen::Vector3d t = T.translation();
    SensorCentredSystem centred;
    // J^T J = [[|y|^2 I - y y^T, [y]x], [-[y]x, I]] for J = [-[y]x, I]: summed as moments.
    double sum_w = 0.0;
    Eigen::Vector3d sum_wy = Eigen::Vector3d::Zero();
    Eigen::Matrix3d sum_wyy = Eigen::Matrix3d::Zero();
    const GaussianVoxel* found[27];
    for (std::size_t i = begin; i < end; ++i) {
      const Eigen::Vector3d y = R * source.points[i].cast<double>(), x = y + t;
      if (!hints.empty())
        map.prefetch_ahead(i, end, hints, [&](std::size_t j) {
          return Eigen::Vector3d(R * source.points[j].cast<double>() + t);
        });
      const int count =
          map.gather_neighbours(x, neighbours, found, hints.empty() ? nullptr : &hints[i]);
      for (int k = 0; k < count; ++k) {
        const GaussianVoxel& v = *found[k];
        if (v.flatness > max_flatness) continue;
        const Eigen::Vector3d r = x - v.mean;
        const double along_normal = v.normal.dot(r);
        const double rr = r.squaredNorm();
        const double s = rr + stiffness * along_normal * along_normal;
        const double w = kernel.weight(s);
        Vector6d g;
        g << y.cross(v.normal), v.normal;
        centred.H.noalias() += (w * stiffness) * g * g.transpose();
        sum_w += w;
        sum_wy += w * y;
        sum_wyy.noalias() += (w * y) * y.transpose();
        // J^T u for the weighted residual u = w (I + k n n^T) r.
        const Eigen::Vector3d u = w * (r + stiffness * along_normal * v.normal);
        centred.b.head<3>() += y.cross(u);
        centred.b.tail<3>() += u;
        if (with_cost) centred.cost += kernel.cost(s);
        centred.squared_error += rr;
        ++centred.inliers;
      }
    }
    const Eigen::Matrix3d sum_wy_skew = skew(sum_wy);
    centred.H.topLeftCorner<3, 3>() += sum_wyy.trace() * Eigen::Matrix3d::Identity() - sum_wyy;
    centred.H.topRightCorner<3, 3>() += sum_wy_skew;
    centred.H.bottomLeftCorner<3, 3>() -= sum_wy_skew;
    centred.H.bottomRightCorner<3, 3>() += sum_w * Eigen::Matrix3d::Identity();
    centred.add_to(system, R);
  }
};

struct CtfFineOptions {
  int max_iterations = 10;    ///< Gauss-Newton steps (each re-pairs every point)
  double tolerance = 1e-5;    ///< m and rad: converged when a step is smaller in both
  int neighbours = 1;         ///< voxels per point: 1 (the paper), 7 or 27
  float max_flatness = 1.0f;  ///< skip voxels less planar than this (1: all, as the paper)
  bool with_cost = true;      ///< false: the result's cost is 0 (saves a logarithm per point)
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
  CtfFineFactor factor{source, map, options.neighbours, options.max_flatness, options.with_cost};
  if (options.neighbours == 1) factor.hints.resize(source.size());
  return optimize(factor, initial, solver);
}

}  // namespace scanmatch
