#pragma once
// What the 2D and 3D loop closures (loop_closure2d.hpp, loop_closure3d.hpp) keep alike: a pose
// graph over keyframes, every added frame as its keyframe followed by the odometry motion from it
// (so a frame's optimized pose follows its keyframe's), and the accepted loops with the outlier
// flags of the last optimize(). The owner adds the keyframe nodes and their odometry edges.

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "scanmatch/mapping/pose_graph.hpp"

namespace scanmatch {

/// A loop edge's information from its registration's Gauss-Newton `hessian` (translation first,
/// then rotation; 3x3 in 2D, 6x6 in 3D): the shape kept, scaled so that the best translation
/// direction has `sigma_translation`; the rotation block's best direction capped at
/// `sigma_rotation` (at that scale it claims the points' lever arm worth of certainty, more than
/// submaps built from odometry poses hold); eigenvalues floored at 1e-6 of the largest so that the
/// graph gets a positive definite matrix even where the geometry leaves a direction free (along a
/// corridor). `fallback` where the Hessian is not usable.
template <int Dim>
typename PoseGraph<Dim>::Information shaped_loop_information(
    const typename PoseGraph<Dim>::Information& hessian, double sigma_translation,
    double sigma_rotation, const typename PoseGraph<Dim>::Information& fallback) {
  using Matrix = typename PoseGraph<Dim>::Information;
  constexpr int kDof = PoseGraph<Dim>::kDof, kRotation = kDof - Dim;
  using Vector = Eigen::Matrix<double, kDof, 1>;
  if (!hessian.allFinite()) return fallback;
  const Matrix H = 0.5 * (hessian + hessian.transpose());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, Dim, Dim>> translation(
      H.template topLeftCorner<Dim, Dim>());
  const double strongest = translation.eigenvalues()(Dim - 1);
  if (!(strongest > 0.0)) return fallback;
  Matrix scaled = H / (strongest * sigma_translation * sigma_translation);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, kRotation, kRotation>> rotation(
      scaled.template bottomRightCorner<kRotation, kRotation>());
  const double rotation_cap = 1.0 / (sigma_rotation * sigma_rotation);
  if (rotation.eigenvalues()(kRotation - 1) > rotation_cap) {
    // Rows and columns scaled alike, so the matrix stays positive semi-definite.
    Vector d = Vector::Ones();
    d.template tail<kRotation>().setConstant(
        std::sqrt(rotation_cap / rotation.eigenvalues()(kRotation - 1)));
    scaled = d.asDiagonal() * scaled * d.asDiagonal();
  }
  const Eigen::SelfAdjointEigenSolver<Matrix> eigen(scaled);
  if (eigen.info() != Eigen::Success) return fallback;
  const double floor = 1e-6 * eigen.eigenvalues().maxCoeff();
  const Vector values = eigen.eigenvalues().cwiseMax(floor);
  if (!(floor > 0.0) || !values.allFinite()) return fallback;
  const Matrix information =
      eigen.eigenvectors() * values.asDiagonal() * eigen.eigenvectors().transpose();
  return 0.5 * (information + information.transpose());
}

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
