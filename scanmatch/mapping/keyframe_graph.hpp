#pragma once
// What the 2D and 3D loop closures (loop_closure2d.hpp, loop_closure3d.hpp) keep alike: a pose
// graph over keyframes, every added frame as its keyframe followed by the odometry motion from it
// (so a frame's optimized pose follows its keyframe's), and the accepted loops with the outlier
// flags of the last optimize(). The owner adds the keyframe nodes and their odometry edges.

#include <algorithm>
#include <cstddef>
#include <vector>

#include "scanmatch/mapping/pose_graph.hpp"

namespace scanmatch {

/// `Loop` has from_keyframe, to_keyframe (graph nodes), relative (to in the frame of from) and a
/// bool outlier.
template <int Dim, class Loop>
class KeyframeGraph {
 public:
  using PoseType = typename PoseGraph<Dim>::PoseType;
  using Information = typename PoseGraph<Dim>::Information;

  explicit KeyframeGraph(const PoseGraphConfig& config) : graph_(config) {}

  PoseGraph<Dim>& graph() { return graph_; }
  const PoseGraph<Dim>& graph() const { return graph_; }

  /// The next frame: its keyframe (a node of graph()) and its odometry pose in that keyframe's
  /// frame.
  void add_frame(std::size_t keyframe, const PoseType& offset) {
    frame_keyframe_.push_back(keyframe);
    frame_offset_.push_back(offset);
  }
  std::size_t frames() const { return frame_keyframe_.size(); }
  std::size_t keyframe_of(std::size_t frame) const { return frame_keyframe_.at(frame); }
  const PoseType& offset_in_keyframe(std::size_t frame) const { return frame_offset_.at(frame); }
  /// The optimized pose of `frame`: its keyframe's, followed by the odometry motion from it.
  PoseType pose(std::size_t frame) const {
    return graph_.pose(keyframe_of(frame)) * offset_in_keyframe(frame);
  }
  std::vector<PoseType> poses() const {
    std::vector<PoseType> out;
    out.reserve(frames());
    for (std::size_t i = 0; i < frames(); ++i) out.push_back(pose(i));
    return out;
  }

  /// Adds `loop` as a loop edge measuring loop.relative between its two keyframes.
  void add_loop(const Loop& loop, const Information& information) {
    loop_edges_.push_back(graph_.add_edge(loop.from_keyframe, loop.to_keyframe, loop.relative,
                                          information, EdgeKind::kLoop));
    loops_.push_back(loop);
  }
  /// Every accepted loop, in order of addition.
  const std::vector<Loop>& loops() const { return loops_; }

  /// Optimizes the graph and flags the loops it judged outliers; returns how many it judged so.
  std::size_t optimize() {
    const PoseGraphSummary s = graph_.optimize();
    const auto& dropped = s.outlier_edges;
    for (std::size_t i = 0; i < loops_.size(); ++i)
      loops_[i].outlier =
          std::find(dropped.begin(), dropped.end(), loop_edges_[i]) != dropped.end();
    return dropped.size();
  }

 private:
  PoseGraph<Dim> graph_;
  std::vector<std::size_t> frame_keyframe_;  ///< per frame, its keyframe
  std::vector<PoseType> frame_offset_;       ///< per frame, its pose in its keyframe's frame
  std::vector<std::size_t> loop_edges_;      ///< graph edge index of each loops_ entry
  std::vector<Loop> loops_;
};

}  // namespace scanmatch
