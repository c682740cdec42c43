#include "scanmatch/registration/methods.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>

#include "scanmatch/core/error.hpp"
#include "scanmatch/geometry/covariance.hpp"
#include "scanmatch/registration/factors/ctf_fine.hpp"
#include "scanmatch/registration/factors/gicp.hpp"
#include "scanmatch/registration/factors/ndt.hpp"
#include "scanmatch/registration/factors/point_to_line.hpp"
#include "scanmatch/registration/factors/point_to_plane.hpp"
#include "scanmatch/registration/factors/point_to_point.hpp"
#include "scanmatch/registration/factors/vgicp.hpp"
#include "scanmatch/registration/loam.hpp"

namespace scanmatch {
namespace {

using Options = RegistrationOptions;

int voxel_neighbours(const Options& o, int method_default) {
  return o.voxel_neighbours > 0 ? o.voxel_neighbours : method_default;
}

// Metric covariances with floored eigenvalues, on the same scale as the voxels' Gaussians.
Eigen::Matrix3d floored_covariance(const Eigen::Matrix3d& C) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(C);
  const Eigen::Vector3d lambda =
      solver.eigenvalues().cwiseMax(1e-3 * std::max(solver.eigenvalues()(2), 1e-6));
  return solver.eigenvectors() * lambda.asDiagonal() * solver.eigenvectors().transpose();
}

RegistrationResult point_to_point(const PointCloud& s, const PointCloud& t, const Options& o,
                                  const Pose& initial, bool use_tree, bool closed_form) {
  const KdTree tree(t.points);  // cheap beside the search; unused by icp-brute
  const PointToPointFactor factor{s, t, use_tree ? &tree : nullptr, o.max_correspondence_distance};
  return closed_form ? icp_closed_form(factor, initial, o.solver)
                     : optimize(factor, initial, o.solver);
}

RegistrationResult icp(const PointCloud& s, const PointCloud& t, const Options& o, const Pose& T) {
  return point_to_point(s, t, o, T, true, true);
}
RegistrationResult icp_brute(const PointCloud& s, const PointCloud& t, const Options& o,
                             const Pose& T) {
  return point_to_point(s, t, o, T, false, true);
}
RegistrationResult icp_gn(const PointCloud& s, const PointCloud& t, const Options& o,
                          const Pose& T) {
  return point_to_point(s, t, o, T, true, false);
}

RegistrationResult point_to_plane(const PointCloud& s, const PointCloud& t, const Options& o,
                                  const Pose& T) {
  const KdTree tree(t.points);
  const auto normals = estimate_normals(t, tree, o.normal_neighbours, o.solver.num_threads);
  return optimize(PointToPlaneFactor{{s, t, tree, o.max_correspondence_distance}, normals}, T,
                  o.solver);
}

RegistrationResult point_to_line(const PointCloud& s, const PointCloud& t, const Options& o,
                                 const Pose& T) {
  const KdTree tree(t.points);
  return optimize(PointToLineFactor{{s, t, tree, o.max_correspondence_distance}}, T, o.solver);
}

RegistrationResult gicp(const PointCloud& s, const PointCloud& t, const Options& o, const Pose& T) {
  const KdTree target_tree(t.points), source_tree(s.points);
  const auto target_covariances = gicp_covariances(t, target_tree, o);
  const auto source_covariances = gicp_covariances(s, source_tree, o);
  return gicp_on({s, source_tree, source_covariances}, {t, target_tree, target_covariances}, o, T);
}

RegistrationResult vgicp(const PointCloud& s, const PointCloud& t, const Options& o,
                         const Pose& T) {
  const KdTree source_tree(s.points);
  auto source_covariances =
      estimate_covariances(s, source_tree, o.covariance_neighbours, o.solver.num_threads);
  for (auto& C : source_covariances) C = floored_covariance(C);
  const GaussianVoxelMap map = registration_voxel_map(t, o);
  return optimize(VgicpFactor{s, source_covariances, map, voxel_neighbours(o, 1)}, T, o.solver);
}

RegistrationResult ndt(const PointCloud& s, const PointCloud& t, const Options& o, const Pose& T) {
  return ndt_on_map(s, registration_voxel_map(t, o), o, T);
}

RegistrationResult ctf_fine(const PointCloud& s, const PointCloud& t, const Options& o,
                            const Pose& T) {
  const GaussianVoxelMap map = registration_voxel_map(t, o);
  CtfFineOptions fine;
  fine.max_iterations = o.solver.max_iterations;
  fine.tolerance = o.solver.translation_tolerance;
  fine.neighbours = voxel_neighbours(o, 1);
  fine.solver = o.solver;
  return register_ctf_fine(s, map, T, fine);
}

RegistrationResult loam(const PointCloud& s, const PointCloud& t, const Options& o, const Pose& T) {
  return register_loam(s, t, LoamResiduals::kBoth, o, T);
}
RegistrationResult loam_edge(const PointCloud& s, const PointCloud& t, const Options& o,
                             const Pose& T) {
  return register_loam(s, t, LoamResiduals::kEdgesOnly, o, T);
}
RegistrationResult loam_plane(const PointCloud& s, const PointCloud& t, const Options& o,
                              const Pose& T) {
  return register_loam(s, t, LoamResiduals::kPlanesOnly, o, T);
}

std::size_t six(const Options&) {
  return 6;
}
std::size_t ten(const Options&) {
  return 10;
}
std::size_t normal_neighbourhood(const Options& o) {
  return static_cast<std::size_t>(std::max(o.normal_neighbours, 6));
}
std::size_t covariance_neighbourhood(const Options& o) {
  return static_cast<std::size_t>(std::max(o.covariance_neighbours, 6));
}
std::size_t loam_neighbourhood(const Options& o) {
  return static_cast<std::size_t>(2 * o.loam.neighbours + 1 + o.loam.segments);
}

const std::vector<RegistrationMethod> kMethods = {
    {"icp", "point-to-point, closed-form SVD step", "k-d tree of the target", six, icp},
    {"icp-kdtree", "the same as icp", "k-d tree of the target", six, icp},
    {"icp-brute", "point-to-point, SVD step, exhaustive search", "nothing it uses", six, icp_brute},
    {"icp-gn", "point-to-point on the Gauss-Newton solver", "k-d tree of the target", six, icp_gn},
    {"point-to-plane", "distance to the target normal's plane", "k-d tree, target normals",
     normal_neighbourhood, point_to_plane},
    {"point-to-line", "distance to the line through the two nearest target points",
     "k-d tree of the target", six, point_to_line},
    {"gicp", "Segal's distribution-to-distribution", "k-d trees, covariances of both clouds",
     covariance_neighbourhood, gicp},
    {"vgicp", "source distributions against target voxel Gaussians",
     "source covariances, Gaussian voxel map of the target", covariance_neighbourhood, vgicp},
    {"ndt", "Magnusson's point-to-distribution score", "Gaussian voxel map of the target", ten,
     ndt},
    {"ctf-fine", "CTF-ICP's fine stage: point to planar voxel Gaussian",
     "Gaussian voxel map of the target", ten, ctf_fine},
    {"loam", "LOAM edges to lines and planar points to planes", "features, k-d trees",
     loam_neighbourhood, loam},
    {"loam-edge", "LOAM edges to lines only", "features, k-d trees", loam_neighbourhood, loam_edge},
    {"loam-plane", "LOAM planar points to planes only", "features, k-d trees", loam_neighbourhood,
     loam_plane},
};

}  // namespace

const std::vector<RegistrationMethod>& registration_methods() {
  return kMethods;
}

std::vector<std::string> registration_method_names() {
  std::vector<std::string> names;
  for (const auto& m : kMethods) names.emplace_back(m.name);
  return names;
}

std::string registration_method_list() {
  std::string list;
  for (const auto& m : kMethods) list += (list.empty() ? "" : ", ") + std::string(m.name);
  return list;
}

bool is_registration_method(const std::string& name) {
  return std::any_of(kMethods.begin(), kMethods.end(),
                     [&](const RegistrationMethod& m) { return name == m.name; });
}

const RegistrationMethod& find_registration_method(const std::string& name) {
  for (const auto& m : kMethods)
    if (name == m.name) return m;
  throw Error("unknown registration method '" + name + "' (valid: " + registration_method_list() +
              ")");
}

std::size_t minimum_points(const std::string& method, const RegistrationOptions& o) {
  return find_registration_method(method).minimum_points(o);
}

RegistrationResult register_clouds(const PointCloud& source, const PointCloud& target,
                                   const RegistrationOptions& o, const Pose& initial) {
  check_registration_inputs(source.size(), target.size(), o, initial);
  return find_registration_method(o.method).run(source, target, o, initial);
}

void check_registration_inputs(std::size_t source_points, std::size_t target_points,
                               const RegistrationOptions& o, const Pose& initial) {
  const std::size_t need = minimum_points(o.method, o);
  if (source_points < need || target_points < need)
    throw Error(o.method + " needs at least " + std::to_string(need) +
                " points in each cloud (source has " + std::to_string(source_points) + ", target " +
                std::to_string(target_points) + ")");
  if (!to_matrix(initial).allFinite()) throw Error("the initial guess is not finite");
}

GaussianVoxelMap registration_voxel_map(const PointCloud& cloud, const RegistrationOptions& o) {
  GaussianVoxelMapOptions m;
  m.voxel_size = o.voxel_resolution;
  m.planar_epsilon = o.ctf_epsilon;
  GaussianVoxelMap map(m);
  map.insert(cloud);
  return map;
}

std::vector<Eigen::Matrix3d> gicp_covariances(const PointCloud& cloud, const KdTree& tree,
                                              const RegistrationOptions& o) {
  std::vector<Eigen::Matrix3d> covariances =
      estimate_covariances(cloud, tree, o.covariance_neighbours, o.solver.num_threads);
  // Segal's plane regularisation: eigenvalues (1, 1, eps).
  for (auto& C : covariances) C = planar_covariance(C, o.gicp_epsilon);
  return covariances;
}

RegistrationResult ndt_on_map(const PointCloud& source, const GaussianVoxelMap& target_map,
                              const RegistrationOptions& o, const Pose& initial) {
  return optimize(ndt_factor(source, target_map, voxel_neighbours(o, 7), o.ndt_outlier_ratio),
                  initial, o.solver);
}

RegistrationResult gicp_on(const GicpCloud& source, const GicpCloud& target,
                           const RegistrationOptions& o, const Pose& initial) {
  return optimize(
      GicpFactor{{source.cloud, target.cloud, target.tree, o.max_correspondence_distance},
                 source.covariances,
                 target.covariances},
      initial, o.solver);
}

double fitness_score(const PointCloud& source, const PointCloud& target, const Pose& T,
                     double max_distance, std::size_t* matched) {
  const KdTree tree(target.points);
  double sum = 0.0;
  std::size_t n = 0;
  for (const Point& p : source.points) {
    std::size_t j;
    float d2;
    if (!tree.nearest((T * p.cast<double>()).cast<float>(),
                      static_cast<float>(max_distance * max_distance), j, d2))
      continue;
    sum += d2;
    ++n;
  }
  if (matched) *matched = n;
  return n > 0 ? sum / static_cast<double>(n) : 0.0;
}

}  // namespace scanmatch
