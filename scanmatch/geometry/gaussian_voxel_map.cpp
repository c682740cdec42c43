#include "scanmatch/geometry/gaussian_voxel_map.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "scanmatch/core/error.hpp"

namespace scanmatch {

GaussianVoxelMap::GaussianVoxelMap(const GaussianVoxelMapOptions& options) : options_(options) {
  if (!(options.voxel_size > 0.0)) throw Error("Gaussian voxel map: voxel size must be positive");
  if (options.merge_threshold == 0)
    throw Error("Gaussian voxel map: merge threshold must be at least 1");
  inverse_size_ = 1.0 / options.voxel_size;
  int exponent = 0;
  exact_inverse_ = std::frexp(options.voxel_size, &exponent) == 0.5;
}

void GaussianVoxelMap::reserve(std::size_t voxels) {
  voxels_.reserve(voxels);
}

void GaussianVoxelMap::clear() {
  voxels_.clear();
}

void GaussianVoxelMap::merge(GaussianVoxel& v, std::uint32_t n, const Eigen::Vector3d& mean,
                             const Eigen::Matrix3d& covariance) {
  if (n == 0) return;
  if (v.count == 0) {
    v.count = n;
    v.mean = mean;
    v.covariance = covariance;
    return;
  }
  const double m = v.count, k = n, total = m + k;
  const Eigen::Vector3d d = v.mean - mean;
  v.covariance = (m * v.covariance + k * covariance + (m * k / total) * d * d.transpose()) / total;
  v.mean = (m * v.mean + k * mean) / total;
  v.count += n;
}

void GaussianVoxelMap::update_cache(GaussianVoxel& v) const {
  // Nothing reads a voxel below min_points; the merge that brings it there computes the cache.
  if (v.count < options_.min_points) return;
  // Closed-form 3x3 eigen decomposition: several times faster than the iterative one, and accurate
  // enough in double precision for normals and regularisation.
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(v.covariance);
  const Eigen::Matrix3d& Q = solver.eigenvectors();  // ascending eigenvalues
  v.normal = Q.col(0);
  const Eigen::Vector3d& e = solver.eigenvalues();
  v.flatness = e(1) > 0.0 ? static_cast<float>(std::max(e(0), 0.0) / e(1)) : 1.0f;
  if (!options_.distributions) return;
  const Eigen::Vector3d lambda = e.cwiseMax(1e-3 * std::max(e(2), 1e-6));
  v.regularized_covariance = Q * lambda.asDiagonal() * Q.transpose();
  v.regularized_information = Q * lambda.cwiseInverse().asDiagonal() * Q.transpose();
}

void GaussianVoxelMap::merge_pending(const VoxelKey& index, GaussianVoxel& v) {
  if (v.pending == 0) return;
  const Eigen::Vector3d corner = Eigen::Vector3d(index.x, index.y, index.z) * options_.voxel_size;
  const double n = v.pending;
  const Eigen::Vector3d local_mean = v.pending_sum / n;
  const Eigen::Matrix3d covariance = v.pending_outer / n - local_mean * local_mean.transpose();
  merge(v, v.pending, corner + local_mean, covariance);
  v.pending = 0;
  v.pending_sum.setZero();
  v.pending_outer.setZero();
  update_cache(v);
}

std::size_t GaussianVoxelMap::insert(const PointCloud& cloud, const Pose& pose) {
  std::vector<std::size_t> touched;
  touched.reserve(cloud.size() / 4 + 1);
  const std::uint64_t call = ++insert_calls_;
  for (const Point& point : cloud.points) {
    const Eigen::Vector3d p = pose * point.cast<double>();
    if (!p.allFinite()) continue;
    const VoxelKey index = index_of(p);
    const std::size_t at = voxels_.find_or_insert(index).entry;
    GaussianVoxel& v = voxels_.value(at);
    if (options_.max_points > 0 && v.count >= options_.max_points) continue;
    const Eigen::Vector3d local =
        p - Eigen::Vector3d(index.x, index.y, index.z) * options_.voxel_size;
    if (v.last_insert != call) {
      v.last_insert = call;
      touched.push_back(at);
    }
    ++v.pending;
    v.pending_sum += local;
    v.pending_outer += local * local.transpose();
  }
  std::size_t merged = 0;
  for (const std::size_t at : touched) {
    GaussianVoxel& v = voxels_.value(at);
    if (v.pending >= options_.merge_threshold) {
      merge_pending(voxels_.keys()[at], v);
      ++merged;
    }
  }
  return merged;
}

void GaussianVoxelMap::flush() {
  for (std::size_t i = 0; i < voxels_.size(); ++i)
    merge_pending(voxels_.keys()[i], voxels_.value(i));
}

std::size_t GaussianVoxelMap::remove_far(const Eigen::Vector3d& center, double radius) {
  const double r2 = radius * radius;
  return voxels_.remove_if([&](const VoxelKey& k, const GaussianVoxel& v) {
    const Eigen::Vector3d where =
        v.count > 0 ? v.mean
                    : (Eigen::Vector3d(k.x, k.y, k.z) + Eigen::Vector3d::Constant(0.5)) *
                          options_.voxel_size;
    return (where - center).squaredNorm() > r2;
  });
}

}  // namespace scanmatch
