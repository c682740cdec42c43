#pragma once
// A cloud registered many times (loop closure verifies a keyframe's submap against several
// others, and again at later keyframes) keeps what the methods build from it: its k-d tree, GICP
// covariances, normals and Gaussian voxel map, each built on first use. register_prepared() then
// costs only the solve, with the same result as register_clouds() (methods.hpp).

#include <Eigen/Core>
#include <cstddef>
#include <memory>
#include <optional>
#include <vector>

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/core/se3.hpp"
#include "scanmatch/geometry/gaussian_voxel_map.hpp"
#include "scanmatch/geometry/kdtree.hpp"
#include "scanmatch/registration/options.hpp"
#include "scanmatch/registration/solver.hpp"

namespace scanmatch {

/// A cloud (copied in, never changed) and its structures, built lazily and kept. The structures
/// point into the object, so it neither copies nor moves: hold it by pointer. Not thread-safe.
class PreparedCloud {
 public:
  explicit PreparedCloud(PointCloud cloud);
  PreparedCloud(const PreparedCloud&) = delete;
  PreparedCloud& operator=(const PreparedCloud&) = delete;

  const PointCloud& cloud() const { return cloud_; }
  std::size_t size() const { return cloud_.size(); }

  const KdTree& tree();
  /// GICP's plane-regularised covariances (options' covariance_neighbours, gicp_epsilon,
  /// solver.num_threads); rebuilt when asked with other values.
  const std::vector<Eigen::Matrix3d>& gicp_covariances(const RegistrationOptions& options);
  /// Unit normals of `neighbours`-point neighbourhoods (estimate_normals); rebuilt for another k.
  const std::vector<Eigen::Vector3d>& normals(int neighbours);
  /// The Gaussian voxel map of ndt, vgicp and ctf-fine (options' voxel_resolution, ctf_epsilon);
  /// rebuilt for other values.
  const GaussianVoxelMap& voxel_map(const RegistrationOptions& options);

  /// The cloud downsampled to `voxel` m (voxel_downsample's centroids), itself prepared; kept
  /// for one voxel size, rebuilt for another.
  PreparedCloud& downsampled(double voxel);

  /// Approximate bytes held (the cloud and what has been built).
  std::size_t memory_bytes() const;

 private:
  PointCloud cloud_;
  std::optional<KdTree> tree_;
  std::vector<Eigen::Matrix3d> covariances_;
  int covariance_neighbours_ = 0;
  double gicp_epsilon_ = 0.0;
  std::vector<Eigen::Vector3d> normals_;
  int normal_neighbours_ = 0;
  std::unique_ptr<GaussianVoxelMap> map_;
  double map_resolution_ = 0.0, map_epsilon_ = 0.0;
  std::unique_ptr<PreparedCloud> downsampled_;
  double downsampled_voxel_ = 0.0;
};

/// register_clouds(source.cloud(), target.cloud(), options, initial), the same result, with the
/// structures the two clouds keep: ndt reads the target's voxel map, gicp both k-d trees and
/// covariances. Any other method runs register_clouds. Throws as register_clouds does.
RegistrationResult register_prepared(PreparedCloud& source, PreparedCloud& target,
                                     const RegistrationOptions& options,
                                     const Pose& initial = Pose::Identity());

}  // namespace scanmatch
