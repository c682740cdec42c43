#include "scanmatch/mapping/loop_candidates.hpp"

#include <algorithm>
#include <utility>

namespace scanmatch {
namespace {

template <int Dim, class Descriptor>
LoopCandidates find_candidates(std::size_t keyframe, std::size_t skip_recent,
                               const PoseGraph<Dim>& estimate,
                               const PlaceDatabase<Descriptor>& places,
                               const LoopCandidateOptions& options, std::size_t descriptor_matches,
                               const LoopCandidateReach& reach) {
  LoopCandidates out;
  if (keyframe <= skip_recent) return out;
  out.end = keyframe - skip_recent;
  const typename PoseGraph<Dim>::PoseType here = estimate.pose(keyframe);
  const auto distance = [&](std::size_t k) {
    return (estimate.pose(k).translation() - here.translation()).norm();
  };
  if (options.max_proximity_candidates > 0) {
    std::vector<std::pair<double, std::size_t>> near;
    for (std::size_t k = 0; k < out.end; ++k) {
      const double d = distance(k);
      if (d <= options.proximity_radius) near.emplace_back(d, k);
    }
    std::sort(near.begin(), near.end());
    // Nearest first, but not several neighbours of one visit: they would verify the same loop.
    std::vector<std::size_t> chosen;
    for (const auto& [d, k] : near) {
      if (chosen.size() >= options.max_proximity_candidates) break;
      const bool same_visit = std::any_of(chosen.begin(), chosen.end(), [&](std::size_t c) {
        return (c > k ? c - k : k - c) < skip_recent / 2 + 1;
      });
      if (same_visit) continue;
      chosen.push_back(k);
      out.candidates.push_back({k, false, 0.0});
    }
  }
  if (options.max_descriptor_candidates > 0) {
    const auto found =
        places.query(places.at(keyframe), skip_recent + 1,
                     std::max(descriptor_matches, options.max_descriptor_candidates));
    std::size_t taken = 0;
    for (const PlaceCandidate& c : found) {
      if (taken >= options.max_descriptor_candidates) break;
      if (c.distance > options.max_descriptor_distance || c.index >= out.end) continue;
      const bool known = std::any_of(out.candidates.begin(), out.candidates.end(),
                                     [&](const LoopCandidate& p) { return p.keyframe == c.index; });
      if (known) continue;
      if (reach && distance(c.index) > reach(c.index)) {
        ++out.ruled_out;
        continue;
      }
      out.candidates.push_back({c.index, true, c.yaw});
      ++taken;
    }
  }
  return out;
}

}  // namespace

LoopCandidates find_loop_candidates(std::size_t keyframe, std::size_t skip_recent,
                                    const PoseGraph2D& estimate, const PlaceDatabase2D& places,
                                    const LoopCandidateOptions& options,
                                    std::size_t descriptor_matches,
                                    const LoopCandidateReach& reach) {
  return find_candidates(keyframe, skip_recent, estimate, places, options, descriptor_matches,
                         reach);
}

LoopCandidates find_loop_candidates(std::size_t keyframe, std::size_t skip_recent,
                                    const PoseGraph3D& estimate, const PlaceDatabase3D& places,
                                    const LoopCandidateOptions& options,
                                    std::size_t descriptor_matches,
                                    const LoopCandidateReach& reach) {
  return find_candidates(keyframe, skip_recent, estimate, places, options, descriptor_matches,
                         reach);
}

}  // namespace scanmatch
