#include "scanmatch/registration/methods.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "scanmatch/core/alignment.hpp"
#include "scanmatch/core/error.hpp"
#include "scanmatch/geometry/covariance.hpp"
#include "scanmatch/registration/factors.hpp"
#include "scanmatch/registration/loam.hpp"

namespace scanmatch {

bool PointToPointFactor::nearest(const Eigen::Vector3d& x, std::size_t& index) const {
  const float limit = static_cast<float>(max_distance * max_distance);
  if (tree) {
    float d2;
    return tree->nearest(x.cast<float>(), limit, index, d2);
  }
  const Point q = x.cast<float>();
  float best = limit;
  bool found = false;
  for (std::size_t j = 0; j < target.points.size(); ++j) {
    const float d2 = (target.points[j] - q).squaredNorm();
    if (d2 <= best) {
      best = d2;
      index = j;
      found = true;
    }
  }
  return found;
}

namespace {

// Classic ICP: nearest neighbours, then the closed-form rigid alignment of the pairs (SVD).
RegistrationResult icp_closed_form(const PointToPointFactor& factor, const Pose& initial,
                                   const SolverOptions& options) {
  RegistrationResult result;
  result.stop_reason = "iteration limit";
  Pose T = initial;
  std::vector<Eigen::Vector3d> from, to;
  for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
    result.iterations = iteration + 1;
    from.clear();
    to.clear();
    for (std::size_t i = 0; i < factor.size(); ++i) {
      const Eigen::Vector3d x = T * factor.source.points[i].cast<double>();
      std::size_t j;
      if (!factor.nearest(x, j)) continue;
      from.push_back(x);
      to.push_back(factor.target.points[j].cast<double>());
    }
    if (from.size() < 3) {
      result.stop_reason = "too few correspondences (" + std::to_string(from.size()) + ")";
      break;
    }
    const Pose step = umeyama_alignment(from, to, false).transform;
    T = step * T;
    if (rotation_angle(step) < options.rotation_tolerance &&
        step.translation().norm() < options.translation_tolerance) {
      result.converged = true;
      result.stop_reason = "update below tolerance";
      break;
    }
  }
  result.transform = T;
  finish_result(result, linearize_all(factor, T, options));
  return result;
}

GaussianVoxelMap target_map(const PointCloud& target, const RegistrationOptions& o) {
  GaussianVoxelMapOptions m;
  m.voxel_size = o.voxel_resolution;
  m.planar_epsilon = o.ctf_epsilon;
  GaussianVoxelMap map(m);
  map.insert(target);
  return map;
}

std::vector<Eigen::Matrix3d> regularised_covariances(const PointCloud& cloud, const KdTree& tree,
                                                     const RegistrationOptions& o) {
  std::vector<Eigen::Matrix3d> covariances =
      estimate_covariances(cloud, tree, o.covariance_neighbours, o.solver.num_threads);
  // Segal's plane regularisation: eigenvalues (1, 1, eps).
  for (auto& C : covariances) C = planar_covariance(C, o.gicp_epsilon);
  return covariances;
}

Eigen::Matrix3d floored_covariance(const Eigen::Matrix3d& C) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(C);
  const Eigen::Vector3d lambda =
      solver.eigenvalues().cwiseMax(1e-3 * std::max(solver.eigenvalues()(2), 1e-6));
  return solver.eigenvectors() * lambda.asDiagonal() * solver.eigenvectors().transpose();
}

}  // namespace

// Magnusson's constants of the Gaussian fitted to the mixture of a normal and a uniform outlier
// distribution, for voxel size `resolution` and outlier probability `outlier_ratio`.
void ndt_score_constants(double resolution, double outlier_ratio, double& d1, double& d2) {
  const double c1 = 10.0 * (1.0 - outlier_ratio);
  const double c2 = outlier_ratio / (resolution * resolution * resolution);
  const double d3 = -std::log(c2);
  d1 = -std::log(c1 + c2) - d3;
  d2 = -2.0 * std::log((-std::log(c1 * std::exp(-0.5) + c2) - d3) / d1);
}

std::vector<std::string> registration_method_names() {
  return {"icp",   "icp-kdtree", "icp-brute", "icp-gn", "point-to-plane", "point-to-line", "gicp",
          "vgicp", "ndt",        "ctf-fine",  "loam",   "loam-edge",      "loam-plane"};
}

std::size_t minimum_points(const std::string& method, const RegistrationOptions& o) {
  if (method == "point-to-plane") return static_cast<std::size_t>(std::max(o.normal_neighbours, 6));
  if (method == "gicp" || method == "vgicp")
    return static_cast<std::size_t>(std::max(o.covariance_neighbours, 6));
  if (method == "ndt" || method == "ctf-fine") return 10;
  if (method.rfind("loam", 0) == 0)
    return static_cast<std::size_t>(2 * o.loam.neighbours + 1 + o.loam.segments);
  return 6;
}

RegistrationResult register_clouds(const PointCloud& source, const PointCloud& target,
                                   const RegistrationOptions& o, const Pose& initial) {
  const std::string& m = o.method;
  const auto names = registration_method_names();
  if (std::find(names.begin(), names.end(), m) == names.end()) {
    std::string valid;
    for (const auto& n : names) valid += (valid.empty() ? "" : ", ") + n;
    throw Error("unknown registration method '" + m + "' (valid: " + valid + ")");
  }
  const std::size_t need = minimum_points(m, o);
  if (source.size() < need || target.size() < need)
    throw Error(m + " needs at least " + std::to_string(need) +
                " points in each cloud (source has " + std::to_string(source.size()) + ", target " +
                std::to_string(target.size()) + ")");
  if (!to_matrix(initial).allFinite()) throw Error("the initial guess is not finite");
  const int neighbours = o.voxel_neighbours > 0 ? o.voxel_neighbours : (m == "ndt" ? 7 : 1);

  if (m == "icp" || m == "icp-kdtree" || m == "icp-brute" || m == "icp-gn") {
    const KdTree tree(target.points);
    const PointToPointFactor factor{source, target, m == "icp-brute" ? nullptr : &tree,
                                    o.max_correspondence_distance};
    return m == "icp-gn" ? optimize(factor, initial, o.solver)
                         : icp_closed_form(factor, initial, o.solver);
  }
  if (m == "loam") return register_loam(source, target, LoamResiduals::kBoth, o, initial);
  if (m == "loam-edge") return register_loam(source, target, LoamResiduals::kEdgesOnly, o, initial);
  if (m == "loam-plane")
    return register_loam(source, target, LoamResiduals::kPlanesOnly, o, initial);
  if (m == "point-to-plane") {
    const KdTree tree(target.points);
    const auto normals = estimate_normals(target, tree, o.normal_neighbours, o.solver.num_threads);
    return optimize(
        PointToPlaneFactor{source, target, tree, normals, o.max_correspondence_distance}, initial,
        o.solver);
  }
  if (m == "point-to-line") {
    const KdTree tree(target.points);
    return optimize(PointToLineFactor{source, target, tree, o.max_correspondence_distance}, initial,
                    o.solver);
  }
  if (m == "gicp") {
    const KdTree target_tree(target.points), source_tree(source.points);
    const auto target_covariances = regularised_covariances(target, target_tree, o);
    const auto source_covariances = regularised_covariances(source, source_tree, o);
    return optimize(GicpFactor{source, target, target_tree, source_covariances, target_covariances,
                               o.max_correspondence_distance},
                    initial, o.solver);
  }
  if (m == "vgicp") {
    const KdTree source_tree(source.points);
    // Metric covariances (eigenvalues floored), on the same scale as the voxels' Gaussians.
    auto source_covariances =
        estimate_covariances(source, source_tree, o.covariance_neighbours, o.solver.num_threads);
    for (auto& C : source_covariances) C = floored_covariance(C);
    const GaussianVoxelMap map = target_map(target, o);
    return optimize(VgicpFactor{source, source_covariances, map, neighbours}, initial, o.solver);
  }
  const GaussianVoxelMap map = target_map(target, o);
  if (m == "ndt") {
    double d1, d2;
    ndt_score_constants(o.voxel_resolution, o.ndt_outlier_ratio, d1, d2);
    return optimize(NdtFactor{source, map, neighbours, d1, d2}, initial, o.solver);
  }
  return optimize(CtfFineFactor{source, map, neighbours}, initial, o.solver);
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
