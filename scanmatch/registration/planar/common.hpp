#pragma once
// Small helpers the 2D methods share (registration/planar/ only).

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "scanmatch/core/scan2d.hpp"
#include "scanmatch/registration/planar/registration2d.hpp"

namespace scanmatch::planar {

inline std::vector<Eigen::Vector2d> transformed(const std::vector<Eigen::Vector2d>& points,
                                                const Pose2& T) {
  std::vector<Eigen::Vector2d> out(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) out[i] = T * points[i];
  return out;
}

inline Eigen::Vector2d centroid(const std::vector<Eigen::Vector2d>& points) {
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& p : points) c += p;
  return points.empty() ? c : Eigen::Vector2d(c / static_cast<double>(points.size()));
}

/// A step below `tolerance` in translation (m) and rotation (rad): converged.
inline bool small_step(const Pose2& step, double tolerance) {
  return step.translation().norm() < tolerance && std::abs(pose2_angle(step)) < tolerance;
}

/// An iteration caught in a cycle. Where each iteration's pose follows from the one before alone,
/// a pose equal (bit for bit) to the one of p iterations before repeats the last p for good (the
/// pair sets flip between trimmings and the step never shrinks), so what the iteration limit
/// would end with is known now. Cycles of up to kLongest iterations are caught.
class IterationCycle {
 public:
  static constexpr int kLongest = 8;

  /// Called after each iteration that did not converge, with its pose, error and pairs in `r`.
  /// True when the pose closes a cycle: `r` then holds what iteration `max_iterations` would end
  /// with (iterations = max_iterations) and the loop can stop.
  bool closes(Registration2DResult& r, int max_iterations) {
    const int i = r.iterations;
    for (int p = 2; p <= std::min(kLongest, seen_); ++p) {
      if (r.transform.matrix() != at(i - p).transform.matrix()) continue;
      // Periodic from i - p on: iteration max_iterations is the one of the same phase among
      // the last p (its error and pairs, from the pose before it, repeat likewise).
      const int ahead = (max_iterations - i) % p;
      if (ahead != 0) {
        const State& s = at(i - p + ahead);
        r.transform = s.transform;
        r.error = s.error;
        r.pairs = s.pairs;
      }
      r.iterations = max_iterations;
      return true;
    }
    at(i) = {r.transform, r.error, r.pairs};
    ++seen_;
    return false;
  }

 private:
  struct State {
    Pose2 transform = Pose2::Identity();
    double error = 0.0;
    std::size_t pairs = 0;
  };
  State& at(int iteration) { return last_[static_cast<std::size_t>(iteration % kLongest)]; }
  std::array<State, kLongest> last_;  ///< by iteration, modulo kLongest
  int seen_ = 0;                      ///< iterations stored, all consecutive up to the current one
};

}  // namespace scanmatch::planar
