#pragma once
// The CTF-ICP fine stage (METHODS.md section 1 step 3) as an ICP loop: associate each source point
// with the map voxel it falls in, solve the planar-Gaussian least squares for those fixed pairs
// (Gauss-Newton on the shared solver), re-associate, until the pose stops moving.
//
// Why not re-associate inside every Gauss-Newton step: with one voxel per point the cost jumps
// wherever a point changes voxel, and a solver that only accepts cost-decreasing steps then sticks
// near its initial guess. With odometry's constant-velocity prior that stickiness turns into a
// slow drift. Fixed pairs give a smooth problem per association.

#include <vector>

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/geometry/gaussian_voxel_map.hpp"
#include "scanmatch/registration/solver.hpp"

namespace scanmatch {

struct CtfFineOptions {
  int max_associations = 10;   ///< outer iterations (voxel look-ups of every point)
  int gauss_newton_steps = 2;  ///< inner solver iterations per association
  double tolerance = 1e-5;     ///< m and rad: stop when an association moved the pose less
  float max_flatness = 1.0f;   ///< skip voxels less planar than this (1: all, as the paper)
  SolverOptions solver;        ///< kernel, threads and degeneracy guard of the inner solve
};

/// Registers `source` (sensor frame) onto the map from `initial`; the result's information
/// matrix and condition number are those of the final association.
RegistrationResult register_ctf_fine(const PointCloud& source, const GaussianVoxelMap& map,
                                     const Pose& initial, const CtfFineOptions& options);

}  // namespace scanmatch
