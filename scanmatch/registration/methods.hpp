#pragma once
// The table of 3D registration methods: every method of the three papers and their baselines.
// Each is a factor (registration/factors/, one per file) on the one solver (solver.hpp), plus
// ICP's classic closed-form SVD step. Name lists, validation and CLI help all come from the
// table; adding a method is a factor file and one table entry in methods.cpp.

#include <cstddef>
#include <string>
#include <vector>

#include "scanmatch/core/point_cloud.hpp"
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

/// Mean squared nearest-neighbour distance of the source points under T that have a target point
/// within max_distance (PCL's fitness score), and how many had one.
double fitness_score(const PointCloud& source, const PointCloud& target, const Pose& T,
                     double max_distance, std::size_t* matched = nullptr);

}  // namespace scanmatch
