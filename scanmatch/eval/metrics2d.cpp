#include "scanmatch/eval/metrics2d.hpp"

#include <algorithm>
#include <cmath>

#include "scanmatch/core/error.hpp"
#include "scanmatch/eval/metrics.hpp"

namespace scanmatch {

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
  r.mean_translation = mean_of(translation);
  r.mean_rotation = mean_of(rotation);
  r.median_translation = median_of(translation);
  r.median_rotation = median_of(rotation);
  r.max_translation = *std::max_element(translation.begin(), translation.end());
  r.max_rotation = *std::max_element(rotation.begin(), rotation.end());
  r.failure_rate = static_cast<double>(failures) / static_cast<double>(r.pairs);
  return r;
}

}  // namespace scanmatch
