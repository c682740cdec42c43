#pragma once
// Registration methods by name: every method of the three papers and their baselines, each a
// factor (factors.hpp) on the one solver (solver.hpp), plus ICP's classic closed-form SVD step.

#include <string>
#include <vector>

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/features/loam_features.hpp"
#include "scanmatch/registration/solver.hpp"

namespace scanmatch {

struct RegistrationOptions {
  /// icp (SVD step, k-d tree), icp-kdtree (same), icp-brute (SVD step, exhaustive search),
  /// icp-gn (point-to-point on the Gauss-Newton solver), point-to-plane, point-to-line, gicp,
  /// vgicp, ndt, ctf-fine, loam (edge and planar features), loam-edge, loam-plane.
  std::string method = "gicp";
  double max_correspondence_distance = 1.0;  ///< m, point-based methods
  int normal_neighbours = 10;                ///< k for normals (point-to-plane)
  int covariance_neighbours = 20;            ///< k for covariances (gicp, vgicp)
  double gicp_epsilon = 1e-3;                ///< smallest normalised eigenvalue of GICP covariances
  double voxel_resolution = 1.0;    ///< m, the Gaussian voxel map of vgicp, ndt and ctf-fine
  int voxel_neighbours = 0;         ///< 1, 7 or 27 voxels per point; 0: the method's default
                                    ///< (ndt 7, vgicp 1, ctf-fine 1)
  double ndt_outlier_ratio = 0.55;  ///< Magnusson's outlier probability for the score constants
  double ctf_epsilon = 1e-6;        ///< CTF-ICP's normalised smallest eigenvalue
  LoamFeatureOptions loam;          ///< feature extraction of the loam methods
  SolverOptions solver;
};

/// Registers source onto target from `initial` (a guess of T_target_source). Throws Error for an
/// unknown method or too few points.
RegistrationResult register_clouds(const PointCloud& source, const PointCloud& target,
                                   const RegistrationOptions& options,
                                   const Pose& initial = Pose::Identity());

std::vector<std::string> registration_method_names();

/// Magnusson's NDT score constants d1, d2: the Gaussian fitted to a mixture of a normal and a
/// uniform outlier distribution, for voxel size `resolution` (m) and outlier probability
/// `outlier_ratio`.
void ndt_score_constants(double resolution, double outlier_ratio, double& d1, double& d2);
/// Points a cloud needs for the method (neighbourhoods, a determined system).
std::size_t minimum_points(const std::string& method, const RegistrationOptions& options);

/// Mean squared nearest-neighbour distance of the source points under T that have a target point
/// within max_distance (PCL's fitness score), and how many had one.
double fitness_score(const PointCloud& source, const PointCloud& target, const Pose& T,
                     double max_distance, std::size_t* matched = nullptr);

}  // namespace scanmatch
