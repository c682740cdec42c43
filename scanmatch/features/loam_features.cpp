#include "scanmatch/features/loam_features.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace scanmatch {

std::vector<std::uint16_t> rings_from_elevation(const PointCloud& cloud, int rings) {
  std::vector<double> elevation(cloud.size());
  double lo = 1e9, hi = -1e9;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Point& p = cloud.points[i];
    elevation[i] = std::atan2(p.z(), std::hypot(p.x(), p.y()));
    lo = std::min(lo, elevation[i]);
    hi = std::max(hi, elevation[i]);
  }
  std::vector<std::uint16_t> out(cloud.size(), 0);
  const double span = std::max(hi - lo, 1e-9);
  for (std::size_t i = 0; i < cloud.size(); ++i)
    out[i] = static_cast<std::uint16_t>(
        std::clamp(static_cast<int>((elevation[i] - lo) / span * rings), 0, rings - 1));
  return out;
}

LoamFeatures extract_loam_features(const PointCloud& cloud, const LoamFeatureOptions& o) {
  const std::vector<std::uint16_t> rings =
      cloud.has_ring() ? cloud.ring : rings_from_elevation(cloud, o.rings);
  const int ring_count = rings.empty() ? 0 : *std::max_element(rings.begin(), rings.end()) + 1;
  std::vector<std::vector<std::size_t>> by_ring(static_cast<std::size_t>(ring_count));
  for (std::size_t i = 0; i < cloud.size(); ++i) by_ring[rings[i]].push_back(i);

  LoamFeatures out;
  const int k = o.neighbours;
  std::vector<double> smoothness;
  std::vector<char> excluded;
  std::vector<std::size_t> order;
  for (int r = 0; r < ring_count; ++r) {
    std::vector<std::size_t>& line = by_ring[static_cast<std::size_t>(r)];
    const int n = static_cast<int>(line.size());
    if (n < 2 * k + 1 + o.segments) continue;
    // Scan order: by time when present, else by azimuth.
    if (cloud.has_time())
      std::stable_sort(line.begin(), line.end(),
                       [&](std::size_t a, std::size_t b) { return cloud.time[a] < cloud.time[b]; });
    else
      std::stable_sort(line.begin(), line.end(), [&](std::size_t a, std::size_t b) {
        return std::atan2(cloud.points[a].y(), cloud.points[a].x()) <
               std::atan2(cloud.points[b].y(), cloud.points[b].x());
      });
    smoothness.assign(static_cast<std::size_t>(n), 0.0);
    excluded.assign(static_cast<std::size_t>(n), 0);
    const auto X = [&](int i) {
      return cloud.points[line[static_cast<std::size_t>(i)]].cast<double>();
    };
    for (int i = k; i < n - k; ++i) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      const Eigen::Vector3d xi = X(i);
      for (int j = i - k; j <= i + k; ++j)
        if (j != i) sum += xi - X(j);
      smoothness[static_cast<std::size_t>(i)] = sum.norm() / (2.0 * k * std::max(xi.norm(), 1e-6));
      // Occlusion boundaries and surfaces nearly parallel to the beam give unreliable features.
      const double range = xi.norm();
      if (std::abs(X(i + 1).norm() - range) > o.occlusion_ratio * range ||
          std::abs(X(i - 1).norm() - range) > o.occlusion_ratio * range)
        excluded[static_cast<std::size_t>(i)] = 1;
    }
    for (int i = 0; i < k; ++i)
      excluded[static_cast<std::size_t>(i)] = excluded[static_cast<std::size_t>(n - 1 - i)] = 1;
    for (int s = 0; s < o.segments; ++s) {
      const int begin = k + (n - 2 * k) * s / o.segments,
                end = k + (n - 2 * k) * (s + 1) / o.segments;
      order.resize(static_cast<std::size_t>(end - begin));
      std::iota(order.begin(), order.end(), static_cast<std::size_t>(begin));
      std::sort(order.begin(), order.end(),
                [&](std::size_t a, std::size_t b) { return smoothness[a] > smoothness[b]; });
      const auto take = [&](std::size_t i, PointCloud& into) {
        into.points.push_back(cloud.points[line[i]]);
        into.ring.push_back(static_cast<std::uint16_t>(r));
        if (cloud.has_time()) into.time.push_back(cloud.time[line[i]]);
        for (int j = -k; j <= k; ++j) {  // no two features next to each other
          const int m = static_cast<int>(i) + j;
          if (m >= 0 && m < n) excluded[static_cast<std::size_t>(m)] = 1;
        }
      };
      int edges = 0;
      for (std::size_t i : order) {
        if (edges >= o.edges_per_segment || smoothness[i] <= o.edge_threshold) break;
        if (excluded[i]) continue;
        take(i, out.edges);
        ++edges;
      }
      int planes = 0;
      for (auto it = order.rbegin(); it != order.rend(); ++it) {
        if (planes >= o.planes_per_segment || smoothness[*it] >= o.plane_threshold) break;
        if (excluded[*it]) continue;
        take(*it, out.planes);
        ++planes;
      }
    }
  }
  return out;
}

}  // namespace scanmatch
