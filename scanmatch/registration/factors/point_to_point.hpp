#pragma once
// Point-to-point: r = T p - q, q the nearest target point (k-d tree, or exhaustive search). Also
// classic ICP's closed-form step (Umeyama/SVD on the pairs), which is its own small solver.

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/geometry/kdtree.hpp"
#include "scanmatch/registration/solver.hpp"

namespace scanmatch {

struct PointToPointFactor {
  const PointCloud& source;
  const PointCloud& target;
  const KdTree* tree;  ///< nullptr: brute-force nearest neighbour
  double max_distance;
  std::size_t size() const { return source.size(); }
  bool nearest(const Eigen::Vector3d& x, std::size_t& index) const;
  bool linearize(const Pose& T, std::size_t i, LinearSystem& system,
                 const RobustKernel& kernel) const {
    const Eigen::Vector3d p = source.points[i].cast<double>(), x = T * p;
    std::size_t j;
    if (!nearest(x, j)) return false;
    const Eigen::Vector3d r = x - target.points[j].cast<double>();
    system.add<3>(point_jacobian(T, p), r, Eigen::Matrix3d::Identity(), kernel);
    return true;
  }
};

/// Classic ICP: nearest neighbours, then the closed-form rigid alignment of the pairs, repeated
/// until the step is below the solver's tolerances.
RegistrationResult icp_closed_form(const PointToPointFactor& factor, const Pose& initial,
                                   const SolverOptions& options);

}  // namespace scanmatch
