#include "scanmatch/features/angle_histogram.hpp"

#include <algorithm>
#include <cmath>

#include "scanmatch/core/error.hpp"

namespace scanmatch {

std::vector<double> angle_histogram(const std::vector<Eigen::Vector2d>& points, double bin_width,
                                    double max_segment, double min_segment) {
  if (!(bin_width > 0.0) || bin_width > M_PI)
    throw Error("angle histogram: bin width must be in (0, pi]");
  // A whole number of equal bins around the circle, so that the correlation can wrap.
  const std::size_t bins =
      std::max<std::size_t>(2, static_cast<std::size_t>(std::lround(2 * M_PI / bin_width)));
  const double width = 2 * M_PI / static_cast<double>(bins);
  std::vector<double> h(bins, 0.0);
  // A segment between neighbours a few centimetres apart has a direction noise of tens of degrees
  // at 1 % range noise; each segment is extended along the scan until it is `min_segment` long.
  for (std::size_t i = 0; i + 1 < points.size(); ++i) {
    std::size_t k = i + 1;
    while (k + 1 < points.size() && (points[k] - points[i]).norm() < min_segment &&
           (points[k] - points[k - 1]).norm() <= max_segment)
      ++k;
    const Eigen::Vector2d d = points[k] - points[i];
    const double length = d.norm();
    if (length < 1e-9 || length > max_segment * static_cast<double>(k - i)) continue;
    if ((points[k] - points[k - 1]).norm() > max_segment) continue;  // crosses a gap
    double angle = std::atan2(d.y(), d.x());
    if (angle < 0) angle += 2 * M_PI;
    h[std::min(bins - 1, static_cast<std::size_t>(angle / width))] += 1.0;
  }
  return h;
}

double histogram_rotation(const std::vector<double>& current, const std::vector<double>& reference,
                          double max_rotation) {
  const std::size_t n = current.size();
  if (n == 0 || reference.size() != n) throw Error("angle histograms differ in size");
  // Shift s turns current by s bins; shifts beyond max_rotation either way are not candidates
  // and are not computed (their neighbours are, for the parabola).
  const double width = 2 * M_PI / static_cast<double>(n);
  const auto allowed = [&](std::size_t s) {
    const double angle = static_cast<double>(s) * width;
    return std::min(angle, 2 * M_PI - angle) <= max_rotation + 1e-12;
  };
  std::vector<double> w(n, 0.0);
  for (std::size_t shift = 0; shift < n; ++shift) {
    if (!allowed(shift) && !allowed((shift + 1) % n) && !allowed((shift + n - 1) % n)) continue;
    double sum = 0.0;  // two plain loops instead of a modulo per bin
    for (std::size_t i = 0; i + shift < n; ++i) sum += current[i] * reference[i + shift];
    for (std::size_t i = n - shift; i < n; ++i) sum += current[i] * reference[i + shift - n];
    w[shift] = sum;
  }
  std::size_t best = 0;
  for (std::size_t s = 1; s < n; ++s)
    if (allowed(s) && w[s] > w[best]) best = s;
  // Parabola through the peak and its neighbours gives the sub-bin offset.
  const double a = w[(best + n - 1) % n], b = w[best], c = w[(best + 1) % n];
  const double denominator = a - 2 * b + c;
  const double offset = std::abs(denominator) > 1e-12 ? 0.5 * (a - c) / denominator : 0.0;
  double rotation = (static_cast<double>(best) + offset) * width;
  while (rotation > M_PI) rotation -= 2 * M_PI;
  while (rotation <= -M_PI) rotation += 2 * M_PI;
  return rotation;
}

}  // namespace scanmatch
