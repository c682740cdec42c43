#include "scanmatch/geometry/covariance.hpp"

#include <Eigen/Eigenvalues>

#include "scanmatch/core/parallel.hpp"

namespace scanmatch {

Eigen::Matrix3d planar_covariance(const Eigen::Matrix3d& C, double epsilon) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(C);
  const Eigen::Matrix3d& Q = solver.eigenvectors();  // eigenvalues ascending
  return Q * Eigen::Vector3d(epsilon, 1.0, 1.0).asDiagonal() * Q.transpose();
}

Eigen::Vector3d smallest_eigenvector(const Eigen::Matrix3d& C) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(C);
  return solver.eigenvectors().col(0);
}

namespace {

Eigen::Matrix3d neighbourhood_covariance(const PointCloud& cloud, const KdTree& tree, std::size_t i,
                                         int k) {
  std::size_t indices[64];
  float distances[64];
  const std::size_t found =
      tree.knn(cloud.points[i], static_cast<std::size_t>(std::min(k, 64)), indices, distances);
  if (found < 3) return Eigen::Matrix3d::Identity() * 1e-2;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
  for (std::size_t j = 0; j < found; ++j) {
    const Eigen::Vector3d p = cloud.points[indices[j]].cast<double>();
    mean += p;
    sum += p * p.transpose();
  }
  mean /= static_cast<double>(found);
  return sum / static_cast<double>(found) - mean * mean.transpose();
}
}  // namespace

std::vector<Eigen::Matrix3d> estimate_covariances(const PointCloud& cloud, const KdTree& tree,
                                                  int k, int num_threads) {
  std::vector<Eigen::Matrix3d> out(cloud.size());
  for_each_index(cloud.size(), num_threads, 256,
                 [&](std::size_t i) { out[i] = neighbourhood_covariance(cloud, tree, i, k); });
  return out;
}

std::vector<Eigen::Vector3d> estimate_normals(const PointCloud& cloud, const KdTree& tree, int k,
                                              int num_threads) {
  std::vector<Eigen::Vector3d> out(cloud.size());
  for_each_index(cloud.size(), num_threads, 256, [&](std::size_t i) {
    out[i] = smallest_eigenvector(neighbourhood_covariance(cloud, tree, i, k));
  });
  return out;
}

}  // namespace scanmatch
