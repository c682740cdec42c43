#pragma once
// The one voxel key of the library: the integer coordinate of a cubic voxel, how a point finds
// it, and its hash. Shared by the voxel filter, the Gaussian voxel map and the exported map.

#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <cstdint>

namespace scanmatch {

struct VoxelKey {
  std::int32_t x = 0, y = 0, z = 0;
  bool operator==(const VoxelKey&) const = default;
};

/// floor(x) as an integer, exact for |x| < 2^31 (larger values and NaN are the caller's to
/// reject): truncation plus a correction. Without SSE4.1 (no -march) std::floor is ~18
/// instructions; this is 4, and in the odometry's hash probes it is the faster one in double too.
inline std::int32_t floor_to_int(float x) {
  const auto t = static_cast<std::int32_t>(x);
  return t - static_cast<std::int32_t>(x < static_cast<float>(t));
}
inline std::int32_t floor_to_int(double x) {
  const auto t = static_cast<std::int32_t>(x);
  return t - static_cast<std::int32_t>(x < static_cast<double>(t));
}

/// The voxel of a point already in voxel units (divided by the voxel size). The voxel filter
/// scales in float by the inverse size (its points are float; in double, about 1 coordinate in
/// 10^5 lands in another voxel at 0.1 m).
template <typename Derived>
inline VoxelKey voxel_key_scaled(const Eigen::MatrixBase<Derived>& s) {
  return {floor_to_int(s.x()), floor_to_int(s.y()), floor_to_int(s.z())};
}

/// The voxel of `p` in a grid of `size` metres, floor(p / size) in double: the Gaussian voxel map
/// and the exported map. A division, not a product by 1 / size: the two differ by a rounding, so
/// a point within it of a voxel face would change voxel (none at sizes that are powers of two).
inline VoxelKey voxel_key(const Eigen::Vector3d& p, double size) {
  const Eigen::Vector3d s = p / size;
  return voxel_key_scaled(s);
}

/// Multiply-xor of the three coordinates, then an avalanche, so that the low bits (the slot of
/// an open-addressing table) depend on every coordinate bit and neighbouring voxels spread out.
struct VoxelKeyHash {
  std::size_t operator()(const VoxelKey& k) const {
    std::uint64_t h =
        static_cast<std::uint64_t>(static_cast<std::uint32_t>(k.x)) * 0x9E3779B97F4A7C15ull;
    h ^= static_cast<std::uint64_t>(static_cast<std::uint32_t>(k.y)) * 0xC2B2AE3D27D4EB4Full;
    h ^= static_cast<std::uint64_t>(static_cast<std::uint32_t>(k.z)) * 0x165667B19E3779F9ull;
    h ^= h >> 29;
    h *= 0xBF58476D1CE4E5B9ull;
    return static_cast<std::size_t>(h ^ (h >> 32));
  }
};

}  // namespace scanmatch
