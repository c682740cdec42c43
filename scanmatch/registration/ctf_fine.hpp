#pragma once
// The CTF-ICP fine stage (METHODS.md section 1 step 3): each source point is paired with the map
// voxel it falls in, and the planar-Gaussian cost sum d^T C'^-1 d (C' with eigenvalues
// (1, 1, eps)) is minimised by Gauss-Newton, re-pairing at every step. Plain Gauss-Newton, not
// Levenberg-Marquardt: with one voxel per point the cost jumps where a point changes voxel, and a
// solver that only accepts cost-decreasing steps sticks near its initial guess.

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/geometry/gaussian_voxel_map.hpp"
#include "scanmatch/registration/solver.hpp"

namespace scanmatch {

struct CtfFineOptions {
  int max_iterations = 10;    ///< Gauss-Newton steps (each re-pairs every point)
  double tolerance = 1e-5;    ///< m and rad: converged when a step is smaller in both
  float max_flatness = 1.0f;  ///< skip voxels less planar than this (1: all, as the paper)
  SolverOptions solver;       ///< kernel, threads and degeneracy guard (its iteration limits and
                              ///< LM switch are not used)
};

/// Registers `source` (sensor frame) onto the map from `initial`; the result's information
/// matrix and condition number are those of the last linearisation.
RegistrationResult register_ctf_fine(const PointCloud& source, const GaussianVoxelMap& map,
                                     const Pose& initial, const CtfFineOptions& options);

}  // namespace scanmatch
