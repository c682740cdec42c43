#include "scanmatch/odometry/elevation_estimate.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "scanmatch/core/statistics.hpp"

namespace scanmatch {
namespace {

constexpr double kRadiansPerDegree = M_PI / 180.0;
constexpr double kMaxPairError = 0.5 * kRadiansPerDegree;
/// The median's standard error at which the pairs have said enough before kMaxPairs.
constexpr double kSettledError = 0.02 * kRadiansPerDegree;
constexpr double kMinCorrection = 0.15 * kRadiansPerDegree;
constexpr double kSignificance = 4.0;

}  // namespace

double ElevationEstimate::median() const {
  return median_of(biases_);
}

double ElevationEstimate::median_error() const {
  if (biases_.size() < 2) return std::numeric_limits<double>::infinity();
  // The pairs' spread from their interquartile range (a standard deviation is 1.349 of it), scaled
  // to the median of n values (sqrt(pi / 2) / sqrt(n)): robust to a quarter of outlying pairs
  // (riverside's 40 m steps), and not fooled, as the median absolute deviation is, by pairs in two
  // camps. The pairs' own error bars are not used: the scenes' shapes exceed them (riverside: 0.3
  // deg between pairs against 0.07 per pair).
  std::vector<double> sorted = biases_;
  std::sort(sorted.begin(), sorted.end());
  const auto quantile = [&](double q) {
    const double at = q * static_cast<double>(sorted.size() - 1);
    const auto below = static_cast<std::size_t>(at);
    const std::size_t above = std::min(below + 1, sorted.size() - 1);
    return sorted[below] + (at - static_cast<double>(below)) * (sorted[above] - sorted[below]);
  };
  const double spread = (quantile(0.75) - quantile(0.25)) / 1.349;
  return spread * std::sqrt(M_PI / 2.0 / static_cast<double>(biases_.size()));
}

void ElevationEstimate::add(const ElevationBiasFromPair& pair) {
  if (decided_ || !(pair.standard_error <= kMaxPairError) || !std::isfinite(pair.bias)) return;
  biases_.push_back(pair.bias);
  if (biases_.size() < kMinPairs) return;
  // The correction follows the pairs' median while it is clear, so that a biased sensor's frames
  // are corrected from early on; the estimate settles at kSettledError or kMaxPairs.
  const double error = median_error();
  const double bias = median();
  const bool clear = std::abs(bias) >= kMinCorrection && std::abs(bias) >= kSignificance * error;
  correction_ = clear ? bias : 0.0;
  decided_ = error <= kSettledError || biases_.size() >= kMaxPairs;
}

}  // namespace scanmatch
