#pragma once
// Point-to-point ICP in 2D: the closed-form SVD step, and the icp and icp-kdtree methods
// (nearest neighbours by brute force or by a k-d tree), which normal-icp reuses.

#include <Eigen/Core>
#include <functional>
#include <vector>

#include "scanmatch/core/scan2d.hpp"
#include "scanmatch/registration/planar/registration2d.hpp"

namespace scanmatch {

/// Rigid transform minimising sum |R p_i + t - q_i|^2 (SVD with reflection guard). Needs two
/// pairs or more; throws Error otherwise.
Pose2 align_svd(const std::vector<Eigen::Vector2d>& from, const std::vector<Eigen::Vector2d>& to);

namespace planar {

/// Point pairs for the SVD step, and the sum of their distances.
struct PointPairs {
  std::vector<Eigen::Vector2d> from, to;
  double distance_sum = 0.0;
  void clear() {
    from.clear();
    to.clear();
    distance_sum = 0.0;
  }
};

/// Whether to keep the pair of current point i and reference point j, R being the rotation of the
/// current pose.
using PairFilter = std::function<bool(std::size_t i, std::size_t j, const Eigen::Matrix2d& R)>;

/// Point-to-point ICP: each current point against its nearest reference point within the
/// correspondence distance (brute force, or the reference's k-d tree with `use_tree`), pairs
/// passing `keep` (empty: all), then the SVD step.
Registration2DResult point_to_point_icp(const Scan2D& current, const Reference2D& reference,
                                        const Registration2DOptions& options, const Pose2& initial,
                                        bool use_tree, const PairFilter& keep = {});

}  // namespace planar
}  // namespace scanmatch
