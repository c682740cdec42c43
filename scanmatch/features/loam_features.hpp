#pragma once
// LOAM-style features (docs/methods.md section 3): per ring, the smoothness
//   c_i = |sum_{j in S, j != i} (X_i - X_j)| / (|S| |X_i|)
// over k neighbours on each side; each ring is cut into equal segments and each segment gives its
// sharpest points (edges) and flattest points (planes).

#include <cstdint>
#include <vector>

#include "scanmatch/core/point_cloud.hpp"

namespace scanmatch {

struct LoamFeatureOptions {
  int neighbours = 5;              ///< k points on each side on the same ring
  int segments = 6;                ///< equal segments per ring
  int edges_per_segment = 2;       ///< the paper's 2 edge points ...
  int planes_per_segment = 4;      ///< ... and 4 planar points per segment
  double edge_threshold = 0.01;    ///< c above this can be an edge
  double plane_threshold = 0.005;  ///< c below this can be planar
  double occlusion_ratio =
      0.1;         ///< neighbour range jump (relative) that marks an occlusion boundary
  int rings = 64;  ///< ring count for clouds without a ring field
};

struct LoamFeatures {
  PointCloud edges, planes;  ///< with the ring field set
};

/// Ring of each point from its elevation angle: the cloud's elevation span cut into `rings` bands.
std::vector<std::uint16_t> rings_from_elevation(const PointCloud& cloud, int rings);

LoamFeatures extract_loam_features(const PointCloud& cloud, const LoamFeatureOptions& options = {});

}  // namespace scanmatch
