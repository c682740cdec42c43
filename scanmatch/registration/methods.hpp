#pragma once
// The table of 3D registration methods: every method of the three papers and their baselines.
// Each is a factor (registration/factors/, one per file) on the one solver (solver.hpp), plus
// ICP's classic closed-form SVD step. Name lists, validation and CLI help all come from the
// table; adding a method is a factor file and one table entry in methods.cpp.

#include <cstddef>
#include <string>
#include <vector>

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/geometry/gaussian_voxel_map.hpp"
#include "scanmatch/geometry/kdtree.hpp"
#include "scanmatch/registration/options.hpp"
#include "scanmatch/registration/solver.hpp"

namespace scanmatch {

struct RegistrationMethod {
  const char* name;
  const char* summary;  ///< one line: the residual and the step
  const char* builds;   ///< what it builds before iterating (trees, normals, covariances, maps)
  /// Points each cloud needs (neighbourhoods, a determined system).
  std::size_t (*minimum_points)(const RegistrationOptions& options);
  RegistrationResult (*run)(const PointCloud& source, const PointCloud& target,
                            const RegistrationOptions& options, const Pose& initial);
};

/// Every method, in the order the CLI lists them.
const std::vector<RegistrationMethod>& registration_methods();
/// The method called `name`; throws Error "unknown registration method 'x' (valid: ...)".
const RegistrationMethod& find_registration_method(const std::string& name);
bool is_registration_method(const std::string& name);
std::vector<std::string> registration_method_names();
/// "icp, icp-kdtree, ..." for help texts and errors.
std::string registration_method_list();
/// Points a cloud needs for the method; throws Error for an unknown method.
std::size_t minimum_points(const std::string& method, const RegistrationOptions& options);

/// Registers source onto target from `initial` (a guess of T_target_source). Throws Error for an
/// unknown method, too few points or a non-finite guess.
RegistrationResult register_clouds(const PointCloud& source, const PointCloud& target,
                                   const RegistrationOptions& options,
                                   const Pose& initial = Pose::Identity());
/// register_clouds' checks of its inputs (throws its errors): a known method, enough points in
/// each cloud, a finite guess.
void check_registration_inputs(std::size_t source_points, std::size_t target_points,
                               const RegistrationOptions& options, const Pose& initial);

/// What some methods build before iterating, and their solves on what was built: register_clouds
/// runs the two halves in turn; a PreparedCloud (prepared_cloud.hpp) keeps the structures.
/// The Gaussian voxel map of ndt, vgicp and ctf-fine (options' voxel_resolution, ctf_epsilon).
GaussianVoxelMap registration_voxel_map(const PointCloud& cloud,
                                        const RegistrationOptions& options);
/// GICP's plane-regularised covariances of each point's covariance_neighbours (gicp_epsilon).
std::vector<Eigen::Matrix3d> gicp_covariances(const PointCloud& cloud, const KdTree& tree,
                                              const RegistrationOptions& options);
/// ndt's solve of `source` against the target's voxel map (registration_voxel_map).
RegistrationResult ndt_on_map(const PointCloud& source, const GaussianVoxelMap& target_map,
                              const RegistrationOptions& options, const Pose& initial);
/// One side of a GICP registration: the cloud, its k-d tree and gicp_covariances.
struct GicpCloud {
  const PointCloud& cloud;
  const KdTree& tree;
  const std::vector<Eigen::Matrix3d>& covariances;
};
/// gicp's solve with both sides' structures built.
RegistrationResult gicp_on(const GicpCloud& source, const GicpCloud& target,
                           const RegistrationOptions& options, const Pose& initial);

/// Mean squared nearest-neighbour distance of the source points under T that have a target point
/// within max_distance (PCL's fitness score), and how many had one.
double fitness_score(const PointCloud& source, const PointCloud& target, const Pose& T,
                     double max_distance, std::size_t* matched = nullptr);

}  // namespace scanmatch
