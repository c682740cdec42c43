#pragma once
// The point cloud: positions stored contiguously (an Eigen 3xN view is free), optional per-point
// fields in parallel arrays that are either empty (field absent) or exactly size() long. A field's
// presence is therefore only visible on a non-empty cloud.

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace scanmatch {

using Point = Eigen::Vector3f;

struct PointCloud {
  std::vector<Point> points;        ///< x y z, metres, in the cloud's frame.
  std::vector<float> intensity;     ///< optional: return strength, sensor units.
  std::vector<std::uint16_t> ring;  ///< optional: laser line index (0 = lowest beam for spinners).
  std::vector<float> time;          ///< optional: seconds since the start of the frame.

  std::size_t size() const { return points.size(); }
  bool empty() const { return points.empty(); }
  bool has_intensity() const { return !intensity.empty(); }
  bool has_ring() const { return !ring.empty(); }
  bool has_time() const { return !time.empty(); }

  /// Positions as a 3xN float matrix, without copying.
  Eigen::Map<const Eigen::Matrix3Xf> matrix() const {
    return {points.empty() ? nullptr : points.front().data(), 3,
            static_cast<Eigen::Index>(points.size())};
  }

  void clear();
  void reserve(std::size_t n);
  /// Resizes every present field with the points (new entries zero).
  void resize(std::size_t n);
  /// True when every optional field is empty or has exactly size() entries.
  bool fields_consistent() const;
};

/// Keeps the points at `indices` (in that order) with all their fields.
PointCloud select(const PointCloud& cloud, const std::vector<std::size_t>& indices);

}  // namespace scanmatch
