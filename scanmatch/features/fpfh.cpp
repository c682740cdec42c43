#include "scanmatch/features/fpfh.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "scanmatch/core/error.hpp"
#include "scanmatch/core/parallel.hpp"
#include "scanmatch/geometry/covariance.hpp"

namespace scanmatch {
namespace {

constexpr int kBinsPerAngle = kFpfhBins / 3;
constexpr std::size_t kMaxNeighbours = 128;

int bin_of(double value, double low, double high) {
  const int b = static_cast<int>(std::floor((value - low) / (high - low) * kBinsPerAngle));
  return std::clamp(b, 0, kBinsPerAngle - 1);
}

struct Neighbour {
  std::size_t index;
  float distance;
};

// The points within `radius` of point i (itself and exact duplicates left out), nearest first.
std::vector<Neighbour> neighbours_within(const PointCloud& cloud, const KdTree& tree, std::size_t i,
                                         const FpfhOptions& options) {
  std::size_t indices[kMaxNeighbours + 1];
  float squared[kMaxNeighbours + 1];
  const std::size_t k =
      std::min<std::size_t>(static_cast<std::size_t>(std::max(options.max_neighbours, 1)),
                            kMaxNeighbours) +
      1;
  const std::size_t found = tree.knn(cloud.points[i], k, indices, squared);
  const float r2 = static_cast<float>(options.radius * options.radius);
  std::vector<Neighbour> out;
  out.reserve(found);
  for (std::size_t j = 0; j < found; ++j)
    if (indices[j] != i && squared[j] > 0.0f && squared[j] <= r2)
      out.push_back({indices[j], std::sqrt(squared[j])});
  return out;
}

// Each third of h scaled to sum to 100 (left at zero when empty).
void normalise_thirds(FpfhDescriptor& h) {
  for (int t = 0; t < 3; ++t) {
    auto part = h.segment<kBinsPerAngle>(t * kBinsPerAngle);
    const float sum = part.sum();
    if (sum > 0.0f) part *= 100.0f / sum;
  }
}

}  // namespace

std::vector<Eigen::Vector3d> oriented_normals(const PointCloud& cloud, const KdTree& tree, int k,
                                              const Eigen::Vector3d& viewpoint, int num_threads) {
  std::vector<Eigen::Vector3d> normals = estimate_normals(cloud, tree, k, num_threads);
  for (std::size_t i = 0; i < normals.size(); ++i)
    if (normals[i].dot(viewpoint - cloud.points[i].cast<double>()) < 0.0) normals[i] = -normals[i];
  return normals;
}

bool fpfh_pair_angles(const Eigen::Vector3d& p, const Eigen::Vector3d& n, const Eigen::Vector3d& q,
                      const Eigen::Vector3d& m, Eigen::Vector3d& angles) {
  Eigen::Vector3d line = q - p;
  const double length = line.norm();
  if (!(length > 0.0)) return false;
  line /= length;
  // The end whose normal is closer to the line is the frame's origin: the pair's angles are then
  // the same whichever point asks.
  Eigen::Vector3d u = n, other = m;
  if (std::abs(n.dot(line)) < std::abs(m.dot(line))) {
    u = m;
    other = n;
    line = -line;
  }
  Eigen::Vector3d v = u.cross(line);
  const double v_norm = v.norm();
  v = v_norm > 1e-12 ? Eigen::Vector3d(v / v_norm) : Eigen::Vector3d(u.unitOrthogonal());
  const Eigen::Vector3d w = u.cross(v);
  angles = Eigen::Vector3d(v.dot(other), u.dot(line), std::atan2(w.dot(other), u.dot(other)));
  return true;
}

std::vector<FpfhDescriptor> compute_fpfh(const PointCloud& cloud, const KdTree& tree,
                                         const std::vector<Eigen::Vector3d>& normals,
                                         const std::vector<std::size_t>& keypoints,
                                         const FpfhOptions& options) {
  if (normals.size() != cloud.size())
    fail("compute_fpfh", "normals (" + std::to_string(normals.size()) + ") and points (" +
                             std::to_string(cloud.size()) + ") differ in number");
  for (std::size_t k : keypoints)
    if (k >= cloud.size())
      fail("compute_fpfh", "keypoint " + std::to_string(k) + " is not a point of the cloud (" +
                               std::to_string(cloud.size()) + " points)");
  if (!(options.radius > 0.0)) fail("compute_fpfh", "the radius must be positive");

  // SPFH of every point that is a keypoint or a keypoint's neighbour; each neighbourhood is
  // searched once (a keypoint's serves both its SPFH and its FPFH).
  std::vector<std::vector<Neighbour>> neighbours(cloud.size());
  std::vector<char> searched(cloud.size(), 0);
  for_each_index(keypoints.size(), options.num_threads, 64, [&](std::size_t k) {
    neighbours[keypoints[k]] = neighbours_within(cloud, tree, keypoints[k], options);
  });
  for (std::size_t k : keypoints) searched[k] = 1;
  std::vector<char> needed(cloud.size(), 0);
  for (std::size_t k : keypoints) {
    needed[k] = 1;
    for (const Neighbour& nb : neighbours[k]) needed[nb.index] = 1;
  }
  std::vector<std::size_t> needed_points, unsearched;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (needed[i]) needed_points.push_back(i);
    if (needed[i] && !searched[i]) unsearched.push_back(i);
  }
  for_each_index(unsearched.size(), options.num_threads, 64, [&](std::size_t j) {
    neighbours[unsearched[j]] = neighbours_within(cloud, tree, unsearched[j], options);
  });
  std::vector<FpfhDescriptor> spfh(cloud.size(), FpfhDescriptor::Zero());
  for_each_index(needed_points.size(), options.num_threads, 64, [&](std::size_t j) {
    const std::size_t i = needed_points[j];
    const Eigen::Vector3d p = cloud.points[i].cast<double>();
    FpfhDescriptor h = FpfhDescriptor::Zero();
    for (const Neighbour& nb : neighbours[i]) {
      Eigen::Vector3d a;
      if (!fpfh_pair_angles(p, normals[i], cloud.points[nb.index].cast<double>(), normals[nb.index],
                            a))
        continue;
      h[bin_of(a[0], -1.0, 1.0)] += 1.0f;
      h[kBinsPerAngle + bin_of(a[1], -1.0, 1.0)] += 1.0f;
      h[2 * kBinsPerAngle + bin_of(a[2], -M_PI, M_PI)] += 1.0f;
    }
    normalise_thirds(h);
    spfh[i] = h;
  });

  std::vector<FpfhDescriptor> out(keypoints.size(), FpfhDescriptor::Zero());
  for_each_index(keypoints.size(), options.num_threads, 64, [&](std::size_t k) {
    const auto& nbs = neighbours[keypoints[k]];
    if (nbs.size() < 3) return;
    FpfhDescriptor neighbours = FpfhDescriptor::Zero();
    for (const Neighbour& nb : nbs) neighbours += spfh[nb.index] / nb.distance;
    normalise_thirds(neighbours);
    out[k] = 0.5f * (spfh[keypoints[k]] + neighbours);
  });
  return out;
}

}  // namespace scanmatch
