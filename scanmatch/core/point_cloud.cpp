#include "scanmatch/core/point_cloud.hpp"

namespace scanmatch {

void PointCloud::clear() {
  points.clear();
  intensity.clear();
  ring.clear();
  time.clear();
}

void PointCloud::reserve(std::size_t n) {
  points.reserve(n);
  if (has_intensity()) intensity.reserve(n);
  if (has_ring()) ring.reserve(n);
  if (has_time()) time.reserve(n);
}

void PointCloud::resize(std::size_t n) {
  points.resize(n, Point::Zero());
  if (has_intensity()) intensity.resize(n, 0.0f);
  if (has_ring()) ring.resize(n, 0);
  if (has_time()) time.resize(n, 0.0f);
}

bool PointCloud::fields_consistent() const {
  const std::size_t n = size();
  return (intensity.empty() || intensity.size() == n) && (ring.empty() || ring.size() == n) &&
         (time.empty() || time.size() == n);
}

PointCloud select(const PointCloud& cloud, const std::vector<std::size_t>& indices) {
  PointCloud out;
  out.points.reserve(indices.size());
  for (std::size_t i : indices) out.points.push_back(cloud.points[i]);
  if (cloud.has_intensity()) {
    out.intensity.reserve(indices.size());
    for (std::size_t i : indices) out.intensity.push_back(cloud.intensity[i]);
  }
  if (cloud.has_ring()) {
    out.ring.reserve(indices.size());
    for (std::size_t i : indices) out.ring.push_back(cloud.ring[i]);
  }
  if (cloud.has_time()) {
    out.time.reserve(indices.size());
    for (std::size_t i : indices) out.time.push_back(cloud.time[i]);
  }
  return out;
}

}  // namespace scanmatch
