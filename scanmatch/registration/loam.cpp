#include "scanmatch/registration/loam.hpp"

#include <cstdlib>

#include "scanmatch/core/error.hpp"
#include "scanmatch/geometry/kdtree.hpp"
#include "scanmatch/registration/factors/loam_edge.hpp"
#include "scanmatch/registration/factors/loam_plane.hpp"

namespace scanmatch {
namespace {

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
  const LoamEdgeFactor edges{
      {source.edges, target.edges, edge_tree, o.max_correspondence_distance}};
  const LoamPlaneFactor planes{
      {source.planes, target.planes, plane_tree, o.max_correspondence_distance}};
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
