#include "scanmatch/registration/loam.hpp"

#include <cstdlib>

#include "scanmatch/core/error.hpp"
#include "scanmatch/geometry/kdtree.hpp"
#include "scanmatch/registration/factors.hpp"

namespace scanmatch {
namespace {

constexpr std::size_t kCandidates = 8;

// Edge point p: nearest target edge q and a neighbour r of q on an adjacent ring; the residual is
// the component of T p - q orthogonal to the line qr (its norm is |(p - q) x (p - r)| / |q - r|).
struct LoamEdgeFactor {
  const PointCloud& source;
  const PointCloud& target;
  const KdTree& tree;
  double max_distance;
  std::size_t size() const { return source.size(); }
  bool linearize(const Pose& T, std::size_t i, LinearSystem& system,
                 const RobustKernel& kernel) const {
    const Eigen::Vector3d p = source.points[i].cast<double>(), x = T * p;
    std::size_t idx[kCandidates];
    float d2[kCandidates];
    const std::size_t found = tree.knn(x.cast<float>(), kCandidates, idx, d2);
    if (found < 2 || d2[0] > max_distance * max_distance) return false;
    const int ring_q = target.ring[idx[0]];
    std::size_t r = idx[1];
    for (std::size_t k = 1; k < found; ++k)
      if (std::abs(static_cast<int>(target.ring[idx[k]]) - ring_q) == 1) {
        r = idx[k];
        break;
      }
    const Eigen::Vector3d q = target.points[idx[0]].cast<double>();
    return add_point_to_line(T, p, q, target.points[r].cast<double>() - q, system, kernel);
  }
};

// Planar point p: nearest planar q, a second point m on q's ring and a third r on an adjacent
// ring; the residual is the signed distance to the plane through q, m, r.
struct LoamPlaneFactor {
  const PointCloud& source;
  const PointCloud& target;
  const KdTree& tree;
  double max_distance;
  std::size_t size() const { return source.size(); }
  bool linearize(const Pose& T, std::size_t i, LinearSystem& system,
                 const RobustKernel& kernel) const {
    const Eigen::Vector3d p = source.points[i].cast<double>(), x = T * p;
    std::size_t idx[kCandidates];
    float d2[kCandidates];
    const std::size_t found = tree.knn(x.cast<float>(), kCandidates, idx, d2);
    if (found < 3 || d2[0] > max_distance * max_distance) return false;
    const int ring_q = target.ring[idx[0]];
    std::size_t m = kCandidates, r = kCandidates;
    for (std::size_t k = 1; k < found; ++k) {
      const int ring = target.ring[idx[k]];
      if (m == kCandidates && ring == ring_q) m = k;
      if (r == kCandidates && std::abs(ring - ring_q) == 1) r = k;
    }
    // Fall back to the nearest other points where the rings do not offer both.
    if (m == kCandidates) m = (r == 1) ? 2 : 1;
    if (r == kCandidates) r = (m == 1) ? 2 : 1;
    const Eigen::Vector3d q = target.points[idx[0]].cast<double>();
    const Eigen::Vector3d n =
        (q - target.points[idx[r]].cast<double>()).cross(q - target.points[idx[m]].cast<double>());
    if (n.squaredNorm() < 1e-10) return false;
    const Eigen::Vector3d normal = n.normalized();
    const Eigen::Matrix<double, 1, 1> residual(normal.dot(x - q));
    system.add<1>(normal.transpose() * point_jacobian(T, p), residual,
                  Eigen::Matrix<double, 1, 1>::Identity(), kernel);
    return true;
  }
};

// Both residual kinds over one index range: edges first, then planes.
struct LoamCombinedFactor {
  const LoamEdgeFactor* edges;
  const LoamPlaneFactor* planes;
  std::size_t size() const { return (edges ? edges->size() : 0) + (planes ? planes->size() : 0); }
  bool linearize(const Pose& T, std::size_t i, LinearSystem& system,
                 const RobustKernel& kernel) const {
    const std::size_t e = edges ? edges->size() : 0;
    return i < e ? edges->linearize(T, i, system, kernel)
                 : planes->linearize(T, i - e, system, kernel);
  }
};

}  // namespace

RegistrationResult register_loam_features(const LoamFeatures& source, const LoamFeatures& target,
                                          LoamResiduals residuals, const RegistrationOptions& o,
                                          const Pose& initial) {
  const bool use_edges = residuals != LoamResiduals::kPlanesOnly,
             use_planes = residuals != LoamResiduals::kEdgesOnly;
  if (use_edges && (source.edges.size() < 3 || target.edges.size() < 3))
    throw Error("loam: too few edge features (source " + std::to_string(source.edges.size()) +
                ", target " + std::to_string(target.edges.size()) + ")");
  if (use_planes && (source.planes.size() < 6 || target.planes.size() < 6))
    throw Error("loam: too few planar features (source " + std::to_string(source.planes.size()) +
                ", target " + std::to_string(target.planes.size()) + ")");
  const KdTree edge_tree(target.edges.points), plane_tree(target.planes.points);
  const LoamEdgeFactor edges{source.edges, target.edges, edge_tree, o.max_correspondence_distance};
  const LoamPlaneFactor planes{source.planes, target.planes, plane_tree,
                               o.max_correspondence_distance};
  return optimize(LoamCombinedFactor{use_edges ? &edges : nullptr, use_planes ? &planes : nullptr},
                  initial, o.solver);
}

RegistrationResult register_loam(const PointCloud& source, const PointCloud& target,
                                 LoamResiduals residuals, const RegistrationOptions& o,
                                 const Pose& initial) {
  return register_loam_features(extract_loam_features(source, o.loam),
                                extract_loam_features(target, o.loam), residuals, o, initial);
}

}  // namespace scanmatch
