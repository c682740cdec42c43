#pragma once
// Fast Point Feature Histograms (Rusu et al., ICRA 2009): a 33-bin, rotation- and
// translation-invariant description of the surface around a point, for matching points between
// clouds with no initial guess (global registration).
//
// For a point p with normal n and a neighbour q with normal m, the Darboux frame u = n,
// v = u x (q - p) / |q - p|, w = u x v gives three angles: alpha = v . m, phi = u . (q - p) / |q -
// p| and theta = atan2(w . m, u . m) (with source and target of the pair swapped when that makes
// the angle between u and the line smaller, so the pair gives one answer). The simplified
// histogram (SPFH) of p bins the three angles of p with each neighbour in 11 bins each; the FPFH
// adds the neighbours' SPFHs weighted by 1 / distance. Each 11-bin third is normalised to sum to
// 100, so descriptors compare by Euclidean distance.

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/geometry/kdtree.hpp"

namespace scanmatch {

inline constexpr int kFpfhBins = 33;
using FpfhDescriptor = Eigen::Matrix<float, kFpfhBins, 1>;

struct FpfhOptions {
  int normal_neighbours = 12;  ///< k nearest points for each normal (at most 64)
  double radius = 2.5;         ///< m, neighbourhood of the histograms
  int max_neighbours = 64;     ///< nearest points within `radius` used at most (bounds the cost)
  /// Normals are turned to face this point: the sensor origin of a cloud in its sensor's frame,
  /// so both clouds see each surface from the side that faced the sensor.
  Eigen::Vector3d viewpoint = Eigen::Vector3d::Zero();
  int num_threads = 1;
};

/// Unit normals from the k nearest neighbours, each turned towards `viewpoint`.
std::vector<Eigen::Vector3d> oriented_normals(const PointCloud& cloud, const KdTree& tree, int k,
                                              const Eigen::Vector3d& viewpoint,
                                              int num_threads = 1);

/// FPFH of the points at `keypoints` of `cloud` (neighbourhoods from the whole cloud, through
/// `tree`, which indexes `cloud`). A point with fewer than 3 neighbours within the radius gets an
/// all-zero descriptor (it matches nothing well). Throws Error for a keypoint out of range.
std::vector<FpfhDescriptor> compute_fpfh(const PointCloud& cloud, const KdTree& tree,
                                         const std::vector<Eigen::Vector3d>& normals,
                                         const std::vector<std::size_t>& keypoints,
                                         const FpfhOptions& options);

/// The three angles (alpha, phi, theta) of the pair (p, n) -> (q, m); false when p == q.
bool fpfh_pair_angles(const Eigen::Vector3d& p, const Eigen::Vector3d& n, const Eigen::Vector3d& q,
                      const Eigen::Vector3d& m, Eigen::Vector3d& angles);

}  // namespace scanmatch
