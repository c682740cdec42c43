#pragma once
// What verifying a loop candidate checks alike in 2D and 3D (loop_verification2d.hpp,
// loop_verification3d.hpp) once the candidate is registered: points paired across within a
// distance, their mean distance, whether the paired surfaces constrain every direction, and
// enough points to tell at all.

#include <cstddef>

namespace scanmatch {

/// The thresholds 2D and 3D verification share. LoopVerification2DOptions and
/// LoopVerification3DOptions inherit them, each with the values of its own scale.
struct LoopVerificationOptions {
  /// After the registration, a point is paired with the other side's nearest point within this
  /// distance, m.
  double pair_distance = 0.0;
  /// Accepted only when the paired points' mean distance is at most this, m.
  double max_error = 0.0;
  /// Degeneracy: the paired points' surface normals must constrain every translation direction:
  /// the smallest eigenvalue of their mean n n^T (eigenvalues sum to 1) must reach this. A
  /// corridor or a tunnel gives ~0 along its axis and would slide to wherever the registration
  /// stopped.
  double min_constraint = 0.0;
  /// Each side needs this many points to be verified at all.
  std::size_t min_points = 0;
};

}  // namespace scanmatch
