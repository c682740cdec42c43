#include "scanmatch/odometry/preprocessor.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

#include "scanmatch/geometry/beam_elevation.hpp"
#include "scanmatch/geometry/voxel_filter.hpp"

namespace scanmatch {
namespace {

/// Frames with this many times min_downsampled_points before the voxel filter are dense.
constexpr std::size_t kDenseFactor = 10;

// The constant-velocity motion over the frame, as a transform into the sensor frame at the
// reference time `reference` (s after the frame start) for each point time. The transform at each
// of kBins instants is exact; between them a first-order step (I + ds xi^) is accurate to
// O(ds^2 |w|^2).
class Deskew {
 public:
  Deskew(const FrameMotion& motion, double max_time, double reference)
      : xi_(se3_log(motion.motion) / motion.period),
        angular_(xi_.head<3>().cast<float>()),
        linear_(xi_.tail<3>().cast<float>()) {
    step_ = std::max(max_time, 1e-6) / (kBins - 1);
    for (int k = 0; k < kBins; ++k)
      bins_[k] = se3_exp(xi_ * (k * step_ - reference)).matrix().cast<float>();
  }
  Point apply(const Point& p, float t) const {
    // Rounding by truncation (not std::lround, a library call per point): equal for t >= 0, and
    // the clamp maps any negative time to the first bin either way.
    const int k = std::clamp(static_cast<int>(t / step_ + 0.5), 0, kBins - 1);
    const float ds = t - static_cast<float>(k * step_);
    const Point q = p + ds * (angular_.cross(p) + linear_);
    return bins_[k].topLeftCorner<3, 3>() * q + bins_[k].topRightCorner<3, 1>();
  }

 private:
  static constexpr int kBins = 64;
  Vector6d xi_;                       ///< twist per second
  Eigen::Vector3f angular_, linear_;  ///< its halves in float, for the per-point step
  double step_;
  Eigen::Matrix4f bins_[kBins];
};

// A dense frame at `voxel_size`, or under `ceiling` points at a larger voxel, filtered from its
// own points. A frame above the ceiling is filtered again at a voxel aimed a little under it (up
// to three times: a spinning sensor's rings thin more slowly than surfaces, so each aim uses how
// the last two passes scaled); the memory carries the voxel to the next frame, which is then
// filtered once. A frame far under the ceiling lets the voxel shrink again (never below
// voxel_size); the band between keeps it from changing every frame.
PointCloud ceiling_downsample(const PointCloud& cloud, double voxel_size, std::uint32_t ceiling,
                              DenseVoxelMemory* memory) {
  constexpr double kAim = 0.85, kShrinkBelow = 0.6;
  constexpr int kMaxPasses = 3;
  if (ceiling == 0) return voxel_downsample(cloud, voxel_size);
  double exponent = 2.0;  // kept points ~ voxel^-exponent: 2 on surfaces, toward 1 along rings
  const auto aimed = [&](double voxel, std::size_t kept) {
    const double ratio = static_cast<double>(kept) / (kAim * ceiling);
    return std::max(voxel_size, voxel * std::pow(ratio, 1.0 / exponent));
  };
  double voxel = memory != nullptr ? std::max(voxel_size, memory->voxel) : voxel_size;
  PointCloud down = voxel_downsample(cloud, voxel);
  if (down.size() > ceiling) {
    for (int pass = 0; pass < kMaxPasses && down.size() > ceiling; ++pass) {
      const double larger = aimed(voxel, down.size());
      PointCloud coarser = voxel_downsample(cloud, larger);
      if (coarser.size() < down.size())
        exponent = std::clamp(
            std::log(static_cast<double>(down.size()) / coarser.size()) / std::log(larger / voxel),
            0.5, 3.0);
      voxel = larger;
      down = std::move(coarser);
    }
    down = thin_to_points(std::move(down), voxel, ceiling);  // the bound, whatever the passes did
  } else if (down.size() < kShrinkBelow * ceiling) {
    voxel = aimed(voxel, down.size());
  }
  if (memory != nullptr) memory->voxel = voxel;
  return down;
}

}  // namespace

PreprocessOptions preprocess_options(const OdometryConfig& config, bool keep_attributes) {
  PreprocessOptions o;
  o.min_range = config.min_range;
  o.max_range = config.max_range;
  o.voxel_size = config.voxel_size;
  o.elevation_correction = config.elevation_correction_deg * M_PI / 180.0;
  o.min_downsampled_points = config.min_downsampled_points;
  o.max_downsampled_points = config.max_downsampled_points;
  o.keep_attributes = keep_attributes;
  return o;
}

float latest_point_time(const PointCloud& frame) {
  float latest = 0.0f;
  for (float t : frame.time)
    if (std::isfinite(t)) latest = std::max(latest, t);
  return latest;
}

bool sparse_frame(std::size_t delivered, const PreprocessOptions& options) {
  return delivered < kDenseFactor * options.min_downsampled_points;
}

PointCloud Preprocessor::crop_and_deskew(const PointCloud& frame, const FrameMotion* motion) const {
  if (!frame.fields_consistent()) return PointCloud{};
  const double min2 = options_.min_range * options_.min_range,
               max2 = options_.max_range * options_.max_range;
  const bool deskew = motion != nullptr && frame.has_time();
  std::optional<Deskew> deskewing;
  if (deskew) deskewing.emplace(*motion, latest_point_time(frame), motion->reference);
  const bool keep_ring = frame.has_ring() && options_.keep_attributes;
  const bool keep_intensity = frame.has_intensity() && options_.keep_attributes;
  const bool corrected = options_.elevation_correction != 0.0;
  const ElevationTurn correction(-options_.elevation_correction);
  PointCloud kept;
  kept.points.reserve(frame.size());
  for (std::size_t i = 0; i < frame.size(); ++i) {
    const Point p = corrected ? correction(frame.points[i]) : frame.points[i];
    const double r2 = p.squaredNorm();
    if (!p.allFinite() || r2 < min2 || r2 > max2) continue;
    if (deskew && std::isfinite(frame.time[i]))
      kept.points.push_back(deskewing->apply(p, frame.time[i]));
    else
      kept.points.push_back(p);
    if (keep_ring) kept.ring.push_back(frame.ring[i]);
    if (keep_intensity) kept.intensity.push_back(frame.intensity[i]);
  }
  return kept;
}

PointCloud Preprocessor::process(const PointCloud& frame, const FrameMotion* motion,
                                 PointCloud* map_points) {
  if (map_points != nullptr) map_points->clear();
  const PointCloud kept = crop_and_deskew(frame, motion);
  if (map_points != nullptr && sparse_frame(frame.size(), options_))
    *map_points = at_map_density(kept);
  return adaptive_downsample(kept, frame.size(), options_, &dense_voxel_);
}

PointCloud Preprocessor::map_detail(const PointCloud& frame, const FrameMotion* motion) const {
  return at_map_density(crop_and_deskew(frame, motion));
}

PointCloud Preprocessor::at_map_density(const PointCloud& kept) const {
  return options_.voxel_size > 0.0 ? voxel_downsample(kept, 0.25 * options_.voxel_size) : kept;
}

PointCloud adaptive_downsample(const PointCloud& cloud, std::size_t delivered,
                               const PreprocessOptions& options, DenseVoxelMemory* memory) {
  if (options.voxel_size <= 0.0) return cloud;
  double voxel = options.voxel_size;
  // Only frames delivered sparse (FAST-LIO keyframes): a dense frame that keeps few points sees a
  // near wall or is mostly within min_range, and finer voxels there did not help (dynamic-indoor:
  // 0.1864 -> 0.1878 % ATE when applied to those frames too).
  if (!sparse_frame(delivered, options))
    return ceiling_downsample(cloud, voxel, options.max_downsampled_points, memory);
  PointCloud down = voxel_downsample(cloud, voxel);
  // Halve the voxel (twice at most) while a sparse frame keeps too few points to register.
  for (int k = 0;
       k < 2 && down.size() < options.min_downsampled_points && down.size() < cloud.size(); ++k) {
    voxel *= 0.5;
    down = voxel_downsample(cloud, voxel);
  }
  return thin_to_points(std::move(down), voxel, options.max_downsampled_points);
}

}  // namespace scanmatch
