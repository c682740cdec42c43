// A cloud's registration structures, kept for many registrations (prepared_cloud.hpp).
#include "scanmatch/registration/prepared_cloud.hpp"

#include <utility>

#include "scanmatch/geometry/covariance.hpp"
#include "scanmatch/geometry/voxel_filter.hpp"
#include "scanmatch/registration/methods.hpp"

namespace scanmatch {
namespace {

// nanoflann's index: one index per point plus about one node per five points (leaves of 10).
constexpr std::size_t kTreeBytesPerPoint = sizeof(std::size_t) + 64 / 5;
// A voxel and its hash slot and key.
constexpr std::size_t kVoxelBytes = sizeof(GaussianVoxel) + sizeof(VoxelKey) + 16;

}  // namespace

PreparedCloud::PreparedCloud(PointCloud cloud) : cloud_(std::move(cloud)) {}

const KdTree& PreparedCloud::tree() {
  if (!tree_) tree_.emplace(cloud_.points);
  return *tree_;
}

const std::vector<Eigen::Matrix3d>& PreparedCloud::gicp_covariances(
    const RegistrationOptions& options) {
  if (covariances_.empty() || covariance_neighbours_ != options.covariance_neighbours ||
      gicp_epsilon_ != options.gicp_epsilon) {
    covariances_ = scanmatch::gicp_covariances(cloud_, tree(), options);
    covariance_neighbours_ = options.covariance_neighbours;
    gicp_epsilon_ = options.gicp_epsilon;
  }
  return covariances_;
}

const std::vector<Eigen::Vector3d>& PreparedCloud::normals(int neighbours) {
  if (normals_.empty() || normal_neighbours_ != neighbours) {
    normals_ = estimate_normals(cloud_, tree(), neighbours);
    normal_neighbours_ = neighbours;
  }
  return normals_;
}

const GaussianVoxelMap& PreparedCloud::voxel_map(const RegistrationOptions& options) {
  if (!map_ || map_resolution_ != options.voxel_resolution || map_epsilon_ != options.ctf_epsilon) {
    map_ = std::make_unique<GaussianVoxelMap>(registration_voxel_map(cloud_, options));
    map_resolution_ = options.voxel_resolution;
    map_epsilon_ = options.ctf_epsilon;
  }
  return *map_;
}

PreparedCloud& PreparedCloud::downsampled(double voxel) {
  if (!downsampled_ || downsampled_voxel_ != voxel) {
    downsampled_ = std::make_unique<PreparedCloud>(voxel_downsample(cloud_, voxel));
    downsampled_voxel_ = voxel;
  }
  return *downsampled_;
}

std::size_t PreparedCloud::memory_bytes() const {
  std::size_t bytes = sizeof(*this) + cloud_.points.capacity() * sizeof(Point);
  if (tree_) bytes += cloud_.size() * kTreeBytesPerPoint;
  bytes += covariances_.capacity() * sizeof(Eigen::Matrix3d);
  bytes += normals_.capacity() * sizeof(Eigen::Vector3d);
  if (map_) bytes += map_->size() * kVoxelBytes;
  if (downsampled_) bytes += downsampled_->memory_bytes();
  return bytes;
}

RegistrationResult register_prepared(PreparedCloud& source, PreparedCloud& target,
                                     const RegistrationOptions& options, const Pose& initial) {
  const bool ndt = options.method == "ndt", gicp = options.method == "gicp";
  if (!ndt && !gicp) return register_clouds(source.cloud(), target.cloud(), options, initial);
  check_registration_inputs(source.size(), target.size(), options, initial);
  if (ndt) return ndt_on_map(source.cloud(), target.voxel_map(options), options, initial);
  return gicp_on({source.cloud(), source.tree(), source.gicp_covariances(options)},
                 {target.cloud(), target.tree(), target.gicp_covariances(options)}, options,
                 initial);
}

}  // namespace scanmatch
