#pragma once
// The first stage of every odometry pipeline (ours and the peers) and of the benchmark's scoring:
// range crop, deskew, and a voxel filter whose size follows the frame.
//
// - Range crop: points nearer than min_range (the robot itself), farther than max_range, or not
//   finite are dropped.
// - Deskew: given the frame's motion, each point with a time is moved to the sensor frame at
//   mid-frame (the reference the registration estimates).
// - Adaptive voxel filter: voxel_size, and for a sparse frame (delivered with fewer than 10 x
//   min_downsampled_points points, e.g. FAST-LIO keyframes) that keeps fewer than
//   min_downsampled_points, smaller voxels (halved at most twice); for a frame that keeps more than
//   max_downsampled_points, larger ones, aimed from the last dense frame (DenseVoxelMemory).

#include <cstddef>
#include <cstdint>

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/core/se3.hpp"
#include "scanmatch/odometry/odometry_config.hpp"

namespace scanmatch {

/// The sensor's motion over one frame, assumed constant: `motion` over `period` s; points are
/// moved to the sensor pose `reference` s after the frame's start.
struct FrameMotion {
  Pose motion = Pose::Identity();
  double period = 0.1;
  double reference = 0.05;
};

struct PreprocessOptions {
  double min_range = 0.3, max_range = 100.0;    ///< m
  double voxel_size = 0.25;                     ///< m (0: no filter)
  double elevation_correction = 0.0;            ///< rad: every point's elevation lowered by this
  std::uint32_t min_downsampled_points = 1000;  ///< point floor of sparse frames (0: off)
  std::uint32_t max_downsampled_points = 0;     ///< point ceiling of every frame (0: off)
  /// Keep rings and intensities (feature methods read them); otherwise only positions are kept.
  bool keep_attributes = true;
};

/// The voxel that kept the last dense frame under the point ceiling. A sensor's consecutive frames
/// are alike, so the next one is filtered once at that voxel instead of at voxel_size and again
/// at a larger one; filtering the points once also keeps centroids of points, not of centroids.
struct DenseVoxelMemory {
  double voxel = 0.0;  ///< m; 0: no dense frame seen yet
};

/// The preprocessing fields of an odometry configuration.
PreprocessOptions preprocess_options(const OdometryConfig& config, bool keep_attributes);

class Preprocessor {
 public:
  explicit Preprocessor(const PreprocessOptions& options) : options_(options) {}
  /// The frame cropped, deskewed by `motion` (when given; points without a finite time stay as
  /// they are) and downsampled. Inconsistent fields (a time per point missing) give an empty cloud.
  /// `map_points`, when given, receives the same frame at map density for a frame delivered
  /// sparse (map_detail), otherwise empty (its registration points serve). Frames above the point
  /// ceiling teach the next frame its voxel (DenseVoxelMemory).
  PointCloud process(const PointCloud& frame, const FrameMotion* motion = nullptr,
                     PointCloud* map_points = nullptr);
  /// The frame cropped and deskewed as by process, filtered at voxel_size / 4 (map density).
  PointCloud map_detail(const PointCloud& frame, const FrameMotion* motion = nullptr) const;
  const PreprocessOptions& options() const { return options_; }
  /// rad: every later frame's elevations lowered by this (PreprocessOptions::elevation_correction).
  void set_elevation_correction(double angle) { options_.elevation_correction = angle; }

 private:
  PointCloud crop_and_deskew(const PointCloud& frame, const FrameMotion* motion) const;
  /// Cropped and deskewed points filtered at voxel_size / 4.
  PointCloud at_map_density(const PointCloud& kept) const;

  PreprocessOptions options_;
  DenseVoxelMemory dense_voxel_;
};

/// The latest finite point time of `frame`, s (0 without times): how long its sweep took.
float latest_point_time(const PointCloud& frame);

/// A frame delivered with `delivered` points is sparse: fewer than 10 x min_downsampled_points.
bool sparse_frame(std::size_t delivered, const PreprocessOptions& options);

/// The adaptive voxel filter alone: voxel_size, then, for a frame delivered with fewer than
/// 10 x min_downsampled_points points (`delivered`, before the range crop), smaller voxels while
/// fewer than min_downsampled_points remain (at most down to voxel_size / 4); then, above
/// max_downsampled_points, filtered at a larger voxel that keeps about that many. With `memory`,
/// a dense frame starts at the voxel the last one needed (and leaves its own there); without, at
/// voxel_size.
PointCloud adaptive_downsample(const PointCloud& cloud, std::size_t delivered,
                               const PreprocessOptions& options,
                               DenseVoxelMemory* memory = nullptr);

}  // namespace scanmatch
