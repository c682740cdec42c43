#include "scanmatch/registration/factors/point_to_point.hpp"

#include <string>
#include <vector>

#include "scanmatch/core/alignment.hpp"

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

}  // namespace scanmatch
