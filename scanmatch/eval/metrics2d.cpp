#include "scanmatch/eval/metrics2d.hpp"

#include <algorithm>
#include <cmath>

#include "scanmatch/core/error.hpp"
#include "scanmatch/eval/metrics.hpp"

namespace scanmatch {

namespace {

void check_sizes(const std::vector<Pose2>& reference, const std::vector<Pose2>& estimate) {
  if (reference.size() != estimate.size())
    throw Error("relative pose error: " + std::to_string(estimate.size()) +
                " estimated poses against " + std::to_string(reference.size()) +
                " reference poses");
}

// The error of every (k, j) pair that `pairs` visits, summarized.
template <typename ForEachPair>
RelativeError2D relative_error_over(const std::vector<Pose2>& reference,
                                    const std::vector<Pose2>& estimate, std::size_t step,
                                    double failure_translation, double failure_rotation,
                                    ForEachPair&& pairs) {
  RelativeError2D r;
  r.step = step;
  std::vector<double> translation, rotation;
  std::size_t failures = 0;
  pairs([&](std::size_t k, std::size_t j) {
    const Pose2 truth = reference[k].inverse() * reference[j];
    const Pose2 est = estimate[k].inverse() * estimate[j];
    const Pose2 error = truth.inverse() * est;
    const double t = error.translation().norm(), a = std::abs(pose2_angle(error));
    translation.push_back(t);
    rotation.push_back(a);
    failures += t > failure_translation || a > failure_rotation;
  });
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

}  // namespace

RelativeError2D relative_pose_error_2d(const std::vector<Pose2>& reference,
                                       const std::vector<Pose2>& estimate, std::size_t step,
                                       double failure_translation, double failure_rotation) {
  check_sizes(reference, estimate);
  if (step == 0) throw Error("relative pose error: the step must be at least 1");
  return relative_error_over(reference, estimate, step, failure_translation, failure_rotation,
                             [&](const auto& visit) {
                               for (std::size_t k = 0; k + step < reference.size(); ++k)
                                 visit(k, k + step);
                             });
}

RelativeError2D all_pairs_relative_error_2d(const std::vector<Pose2>& reference,
                                            const std::vector<Pose2>& estimate,
                                            std::size_t max_poses, double failure_translation,
                                            double failure_rotation) {
  check_sizes(reference, estimate);
  const std::size_t n = reference.size();
  const std::size_t kept = std::min(n, std::max<std::size_t>(max_poses, 2));
  std::vector<std::size_t> index;
  for (std::size_t i = 0; i < kept; ++i) index.push_back(kept < 2 ? 0 : i * (n - 1) / (kept - 1));
  return relative_error_over(reference, estimate, 0, failure_translation, failure_rotation,
                             [&](const auto& visit) {
                               for (std::size_t a = 0; a < index.size(); ++a)
                                 for (std::size_t b = a + 1; b < index.size(); ++b)
                                   visit(index[a], index[b]);
                             });
}

AbsoluteError2D absolute_trajectory_error_2d(const std::vector<Pose2>& reference,
                                             const std::vector<Pose2>& estimate) {
  if (reference.size() != estimate.size())
    throw Error("absolute trajectory error: " + std::to_string(estimate.size()) +
                " estimated poses against " + std::to_string(reference.size()) +
                " reference poses");
  AbsoluteError2D r;
  r.poses = reference.size();
  if (r.poses < 2) return r;
  Eigen::Vector2d mean_ref = Eigen::Vector2d::Zero(), mean_est = Eigen::Vector2d::Zero();
  for (std::size_t i = 0; i < r.poses; ++i) {
    mean_ref += reference[i].translation();
    mean_est += estimate[i].translation();
  }
  mean_ref /= static_cast<double>(r.poses);
  mean_est /= static_cast<double>(r.poses);
  // The rotation angle that best turns the centred estimate onto the centred reference.
  double dot = 0.0, cross = 0.0;
  for (std::size_t i = 0; i < r.poses; ++i) {
    const Eigen::Vector2d e = estimate[i].translation() - mean_est;
    const Eigen::Vector2d f = reference[i].translation() - mean_ref;
    dot += e.dot(f);
    cross += e.x() * f.y() - e.y() * f.x();
  }
  const Eigen::Rotation2Dd rotation(std::atan2(cross, dot));
  r.alignment = Pose2::Identity();
  r.alignment.linear() = rotation.toRotationMatrix();
  r.alignment.translation() = mean_ref - rotation * mean_est;
  double sum = 0.0, sum_squared = 0.0;
  for (std::size_t i = 0; i < r.poses; ++i) {
    const Eigen::Vector2d aligned = rotation * (estimate[i].translation() - mean_est) + mean_ref;
    const double d = (aligned - reference[i].translation()).norm();
    sum += d;
    sum_squared += d * d;
    r.max = std::max(r.max, d);
  }
  r.mean = sum / static_cast<double>(r.poses);
  r.rmse = std::sqrt(sum_squared / static_cast<double>(r.poses));
  return r;
}

}  // namespace scanmatch
