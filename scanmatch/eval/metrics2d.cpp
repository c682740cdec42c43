#include "scanmatch/eval/metrics2d.hpp"

#include <algorithm>
#include <cmath>

#include "scanmatch/core/error.hpp"

namespace scanmatch {
namespace {

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto middle = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), middle, v.end());
  if (v.size() % 2 == 1) return *middle;
  return 0.5 * (*middle + *std::max_element(v.begin(), middle));
}

}  // namespace

RelativeError2D relative_pose_error_2d(const std::vector<Pose2>& reference,
                                       const std::vector<Pose2>& estimate, std::size_t step,
                                       double failure_translation, double failure_rotation) {
  if (reference.size() != estimate.size())
    throw Error("relative pose error: " + std::to_string(estimate.size()) +
                " estimated poses against " + std::to_string(reference.size()) +
                " reference poses");
  if (step == 0) throw Error("relative pose error: the step must be at least 1");
  RelativeError2D r;
  r.step = step;
  std::vector<double> translation, rotation;
  std::size_t failures = 0;
  for (std::size_t k = 0; k + step < reference.size(); ++k) {
    const Pose2 truth = reference[k].inverse() * reference[k + step];
    const Pose2 est = estimate[k].inverse() * estimate[k + step];
    const Pose2 error = truth.inverse() * est;
    const double t = error.translation().norm(), a = std::abs(pose2_angle(error));
    translation.push_back(t);
    rotation.push_back(a);
    failures += t > failure_translation || a > failure_rotation;
  }
  r.pairs = translation.size();
  if (r.pairs == 0) return r;
  const auto mean = [](const std::vector<double>& v) {
    double s = 0.0;
    for (double x : v) s += x;
    return s / static_cast<double>(v.size());
  };
  r.mean_translation = mean(translation);
  r.mean_rotation = mean(rotation);
  r.median_translation = median(translation);
  r.median_rotation = median(rotation);
  r.max_translation = *std::max_element(translation.begin(), translation.end());
  r.max_rotation = *std::max_element(rotation.begin(), rotation.end());
  r.failure_rate = static_cast<double>(failures) / static_cast<double>(r.pairs);
  return r;
}

}  // namespace scanmatch
