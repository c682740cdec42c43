#pragma once
// Closed-form alignment of corresponding point sets (Umeyama 1991), used by point-to-point ICP's
// SVD step and by trajectory evaluation.

#include <vector>

#include "scanmatch/core/se3.hpp"

namespace scanmatch {

/// Least-squares similarity (Umeyama 1991) mapping `from` onto `to`: to ~ s R from + t.
struct Similarity {
  Pose transform = Pose::Identity();  ///< rotation and translation
  double scale = 1.0;
};
Similarity umeyama_alignment(const std::vector<Eigen::Vector3d>& from,
                             const std::vector<Eigen::Vector3d>& to, bool with_scale);

}  // namespace scanmatch
