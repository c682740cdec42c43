#pragma once
// Loop candidates: which earlier keyframes a new keyframe is verified against, alike in 2D and 3D
// (loop_closure2d.hpp, loop_closure3d.hpp). Two sources, merged: the keyframes near the new one in
// the current (optimized) estimate, nearest first and one per visit, and the place database's best
// matches (place_database.hpp) below a descriptor distance, best first. The newest keyframes are
// never candidates: they are the same place trivially.

#include <cstddef>
#include <functional>
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

/// The candidates of `keyframe` (node `keyframe` of `estimate`, entry `keyframe` of `places`)
/// among the keyframes before the newest `skip_recent`. Of the place database, its best
/// `descriptor_matches` matches (at least max_descriptor_candidates) are looked at, best first:
/// look-alike places often match better than the true one, so those farther than `reach` are
/// skipped and the best remaining ones taken.
LoopCandidates find_loop_candidates(std::size_t keyframe, std::size_t skip_recent,
                                    const PoseGraph2D& estimate, const PlaceDatabase2D& places,
                                    const LoopCandidateOptions& options,
                                    std::size_t descriptor_matches = 0,
                                    const LoopCandidateReach& reach = {});
LoopCandidates find_loop_candidates(std::size_t keyframe, std::size_t skip_recent,
                                    const PoseGraph3D& estimate, const PlaceDatabase3D& places,
                                    const LoopCandidateOptions& options,
                                    std::size_t descriptor_matches = 0,
                                    const LoopCandidateReach& reach = {});

}  // namespace scanmatch
