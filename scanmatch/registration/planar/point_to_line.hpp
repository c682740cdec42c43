#pragma once
// The closed-form point-to-line step (Censi 2008), exact through the Lagrange multiplier of the
// rotation's constraint: pl-icp's step, and sparse-icp's on its kept pairs.

#include <Eigen/Core>
#include <vector>

#include "scanmatch/core/scan2d.hpp"

namespace scanmatch {

/// The transform minimising sum (n_i . (R p_i + t - q_i))^2 exactly, through the Lagrange
/// multiplier of the constraint cos^2 + sin^2 = 1. Needs three pairs with non-parallel normals
/// or more; throws Error otherwise.
Pose2 solve_point_to_line(const std::vector<Eigen::Vector2d>& points,
                          const std::vector<Eigen::Vector2d>& line_points,
                          const std::vector<Eigen::Vector2d>& normals);

namespace planar {

/// A point of the current scan against a line of the reference: the point (current frame), a
/// point of the line and its unit normal (reference frame), and the distance at the current pose.
struct LinePair {
  Eigen::Vector2d point, on_line, normal;
  double distance;
};

/// Keeps the `fraction` of pairs nearest to their lines (at least three).
void keep_nearest_fraction(std::vector<LinePair>& pairs, double fraction);

/// The step on the pairs; their mean distance goes to `mean_distance`. A faint pull towards the
/// current pose (1e-6 of the pairs' weight) keeps a degenerate set solvable (a corridor's walls
/// are all parallel): along what the pairs leave free the pose stays where it is, and elsewhere
/// the pull changes nothing measurable.
Pose2 solve_line_pairs(const std::vector<LinePair>& pairs, const Pose2& current,
                       double& mean_distance);

}  // namespace planar
}  // namespace scanmatch
