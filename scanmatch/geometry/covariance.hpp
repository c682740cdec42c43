#pragma once
// Local surface shape from k nearest neighbours: normals and covariances, and the plane-like
// regularisation used by GICP, VGICP and the CTF-ICP map.

#include <Eigen/Core>
#include <vector>

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/geometry/kdtree.hpp"

namespace scanmatch {

/// Replaces C's eigenvalues by (1, 1, epsilon) (largest two to 1), keeping its eigenvectors: a
/// plane through the distribution whose normal is the smallest eigenvector.
Eigen::Matrix3d planar_covariance(const Eigen::Matrix3d& C, double epsilon);
/// Smallest-eigenvalue eigenvector of C (the normal of a planar distribution).
Eigen::Vector3d smallest_eigenvector(const Eigen::Matrix3d& C);

/// Covariance of each point's k nearest neighbours (k >= 3; fewer neighbours give identity * 1e-2).
std::vector<Eigen::Matrix3d> estimate_covariances(const PointCloud& cloud, const KdTree& tree,
                                                  int k, int num_threads = 1);
/// Unit normals from the same neighbourhoods (sign arbitrary).
std::vector<Eigen::Vector3d> estimate_normals(const PointCloud& cloud, const KdTree& tree, int k,
                                              int num_threads = 1);

}  // namespace scanmatch
