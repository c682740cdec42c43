#pragma once
// Point cloud filters: voxel-grid downsampling, range and box crops, removal of non-finite points.
// All keep the optional per-point fields consistent with the points they keep.

#include <Eigen/Geometry>
#include <cstddef>

#include "scanmatch/core/point_cloud.hpp"

namespace scanmatch {

enum class VoxelReduction {
  kCentroid,  ///< one point per voxel at the mean of its points (fields averaged, ring of the
              ///< first)
  kNearestToCentroid,  ///< the original point of each voxel closest to the voxel mean (fields kept)
};

/// One point per occupied voxel of edge `voxel_size` (metres, > 0). Output order is the order in
/// which voxels are first met, so the result is deterministic. Non-finite points are skipped.
/// Hash-based, O(n); throws Error when voxel_size is not positive or a coordinate is too far from
/// the origin for a 32-bit voxel index.
PointCloud voxel_downsample(const PointCloud& cloud, double voxel_size,
                            VoxelReduction reduction = VoxelReduction::kCentroid);

/// `cloud`, already filtered with `voxel` (m), when it holds more than `max_points` (0: no limit):
/// filtered again with a voxel sqrt(size / max_points) times larger, so that about max_points
/// remain (the points of a scan lie on surfaces, whose voxel count falls with the voxel's square).
PointCloud thin_to_points(PointCloud cloud, double voxel, std::size_t max_points);

/// Keeps points whose distance from the origin lies in [min_range, max_range].
PointCloud crop_range(const PointCloud& cloud, double min_range, double max_range);

/// Keeps points inside (`keep_inside`) or outside the axis-aligned box.
PointCloud crop_box(const PointCloud& cloud, const Eigen::AlignedBox3f& box,
                    bool keep_inside = true);

/// Removes points with a NaN or infinite coordinate in place; returns how many were removed.
std::size_t remove_non_finite(PointCloud& cloud);

}  // namespace scanmatch
