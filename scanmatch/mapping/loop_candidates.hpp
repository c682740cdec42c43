#pragma once
// Loop candidates: which earlier keyframes a new keyframe is verified against, alike in 2D and 3D
// (loop_closure2d.hpp, loop_closure3d.hpp). Two sources, merged: the keyframes near the new one in
// the current (optimized) estimate, nearest first and one per visit, and the place database's best
// matches (place_database.hpp) below a descriptor distance, best first. The newest keyframes are
// never candidates: they are the same place trivially.

#include <algorithm>
#include <cstddef>
#include <functional>
#include <utility>
#include <vector>

#include "scanmatch/features/place_database.hpp"
#include "scanmatch/mapping/pose_graph.hpp"

namespace scanmatch {

/// Where candidates come from and how many (LoopClosure2DOptions::candidates,
/// LoopClosure3DOptions::candidates, each with its own defaults).
struct LoopCandidateOptions {
  /// Pose-proximity candidates: earlier keyframes within this distance (m) of the new one in the
  /// current estimate, nearest first, at most `max_proximity_candidates` (0: none), each at least
  /// skip_recent / 2 + 1 keyframes from the others (not two neighbours of one visit, which would
  /// verify the same loop).
  double proximity_radius = 0.0;
  std::size_t max_proximity_candidates = 2;
  /// Place-database candidates below this descriptor distance, at most this many (0: none).
  double max_descriptor_distance = 0.0;
  std::size_t max_descriptor_candidates = 1;
};

struct LoopCandidate {
  std::size_t keyframe = 0;
  /// Found by the place database, which knows the heading only: `yaw` is the new keyframe's
  /// heading in the candidate's frame (PlaceMatch::yaw). Otherwise found by proximity, and the
  /// estimate's relative pose is the start.
  bool by_descriptor = false;
  double yaw = 0.0;
};

struct LoopCandidates {
  /// The proximity candidates (nearest first), then the database's (best first); each keyframe
  /// once.
  std::vector<LoopCandidate> candidates;
  /// Keyframes [0, end) could be candidates; the newer ones are too recent.
  std::size_t end = 0;
  /// Database matches ruled out by `reach` (find_loop_candidates): not candidates.
  std::size_t ruled_out = 0;
};

/// How far (m) a database match of keyframe k may lie from the new keyframe in the estimate and
/// still be a candidate; empty: any distance.
using LoopCandidateReach = std::function<double(std::size_t k)>;

/// The candidates of `keyframe` (node `keyframe` of `estimate`, entry `keyframe` of `places`; 2D
/// or 3D) among the keyframes before the newest `skip_recent`. Of the place database, its best
/// `descriptor_matches` matches (at least max_descriptor_candidates) are looked at, best first:
/// look-alike places often match better than the true one, so those farther than `reach` are
/// skipped and the best remaining ones taken. `proximity`, where given, is keyframe k's proximity
/// radius (default: options.proximity_radius).
template <int Dim, class Descriptor>
LoopCandidates find_loop_candidates(std::size_t keyframe, std::size_t skip_recent,
                                    const PoseGraph<Dim>& estimate,
                                    const PlaceDatabase<Descriptor>& places,
                                    const LoopCandidateOptions& options,
                                    std::size_t descriptor_matches = 0,
                                    const LoopCandidateReach& reach = {},
                                    const LoopCandidateReach& proximity = {}) {
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
      if (d <= (proximity ? proximity(k) : options.proximity_radius)) near.emplace_back(d, k);
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

}  // namespace scanmatch
