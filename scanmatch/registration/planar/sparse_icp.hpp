#pragma once
// sparse-icp, the 2D paper's method (registration2d.hpp lists its stages): its coarse stage is
// exposed here; the method runs through register_scans.

#include <Eigen/Core>
#include <vector>

#include "scanmatch/core/scan2d.hpp"

namespace scanmatch {

/// sparse-icp's coarse stage: the histogram rotation (within `max_rotation`) about the origin,
/// then the translation between the centroids. Returns the correction to apply to `current`.
Pose2 coarse_alignment_2d(const std::vector<Eigen::Vector2d>& current,
                          const std::vector<Eigen::Vector2d>& reference, double bin_width,
                          double max_rotation, bool rotation = true, bool translation = true,
                          double min_segment = 0.0);

}  // namespace scanmatch
