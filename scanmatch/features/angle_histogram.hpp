#pragma once
// Angle histograms of 2D scans (docs/methods.md section 2 step 1): the direction of the line
// through each pair of consecutive points, binned over [0, 2 pi); the circular cross-correlation of
// two histograms peaks at the rotation between the scans.

#include <Eigen/Core>
#include <cmath>
#include <vector>

namespace scanmatch {

/// Directions of the segments between consecutive points (in scan order), binned over
/// [0, 2 pi) in round(2 pi / bin_width) equal bins. A segment is extended to later points until
/// it is at least `min_segment` long (0: the paper's plain neighbours); steps longer than
/// `max_segment` metres (a gap between two objects, not a surface) end it and are skipped.
std::vector<double> angle_histogram(const std::vector<Eigen::Vector2d>& points, double bin_width,
                                    double max_segment = 0.5, double min_segment = 0.0);

/// The rotation (radians, in (-pi, pi]) that turns the directions of `current` into those of
/// `reference`: the peak of w(J) = sum_I h_current(I) h_reference(I + J), refined between bins by
/// a parabola. Only rotations within +- `max_rotation` are considered (pi: all). Both histograms
/// must have the same size.
double histogram_rotation(const std::vector<double>& current, const std::vector<double>& reference,
                          double max_rotation = M_PI);

}  // namespace scanmatch
