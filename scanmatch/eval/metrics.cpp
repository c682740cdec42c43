#include "scanmatch/eval/metrics.hpp"

#include <algorithm>
#include <cmath>

#include "scanmatch/core/error.hpp"

namespace scanmatch {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

void check_same_size(const std::vector<Pose>& a, const std::vector<Pose>& b, const char* what) {
  if (a.size() != b.size())
    fail(what, "ground truth has " + std::to_string(a.size()) + " poses, estimate " +
                   std::to_string(b.size()));
  if (a.empty()) fail(what, "no poses to evaluate");
}

double rms(const std::vector<double>& values) {
  if (values.empty()) return 0.0;
  double sum = 0.0;
  for (double v : values) sum += v * v;
  return std::sqrt(sum / static_cast<double>(values.size()));
}

// Rotation angle as the KITTI devkit computes it (acos of the clamped trace term).
double devkit_rotation_error(const Pose& error) {
  const Eigen::Matrix3d& R = error.linear();
  const double d = 0.5 * (R(0, 0) + R(1, 1) + R(2, 2) - 1.0);
  return std::acos(std::clamp(d, -1.0, 1.0));
}

RpeResult summarise_rpe(const std::vector<double>& translation,
                        const std::vector<double>& rotation) {
  RpeResult r;
  r.pairs = translation.size();
  r.translation_rmse = rms(translation);
  r.translation_mean = mean_of(translation);
  r.translation_median = median_of(translation);
  r.rotation_rmse = rms(rotation);
  r.rotation_mean = mean_of(rotation);
  return r;
}

void add_relative_error(const std::vector<Pose>& gt, const std::vector<Pose>& est, std::size_t i,
                        std::size_t j, std::vector<double>& translation,
                        std::vector<double>& rotation) {
  const Pose error = (est[i].inverse() * est[j]).inverse() * (gt[i].inverse() * gt[j]);
  translation.push_back(error.translation().norm());
  rotation.push_back(rotation_angle(error) * kRadToDeg);
}

}  // namespace

Alignment parse_alignment(const std::string& name) {
  if (name == "none") return Alignment::kNone;
  if (name == "se3") return Alignment::kSe3;
  if (name == "sim3") return Alignment::kSim3;
  fail("--align", "unknown alignment '" + name + "' (expected none, se3 or sim3)");
}

const char* to_string(Alignment alignment) {
  switch (alignment) {
    case Alignment::kNone:
      return "none";
    case Alignment::kSe3:
      return "se3";
    case Alignment::kSim3:
      return "sim3";
  }
  return "?";
}

std::vector<double> cumulative_distances(const std::vector<Pose>& poses) {
  std::vector<double> distances(poses.size(), 0.0);
  for (std::size_t i = 1; i < poses.size(); ++i)
    distances[i] = distances[i - 1] + (poses[i].translation() - poses[i - 1].translation()).norm();
  return distances;
}

AteResult compute_ate(const std::vector<Pose>& ground_truth, const std::vector<Pose>& estimate,
                      Alignment alignment) {
  check_same_size(ground_truth, estimate, "ATE");
  std::vector<Eigen::Vector3d> gt_positions, est_positions;
  for (std::size_t i = 0; i < ground_truth.size(); ++i) {
    gt_positions.push_back(ground_truth[i].translation());
    est_positions.push_back(estimate[i].translation());
  }
  AteResult r;
  r.poses = ground_truth.size();
  if (alignment != Alignment::kNone)
    r.alignment = umeyama_alignment(est_positions, gt_positions, alignment == Alignment::kSim3);
  std::vector<double> errors;
  errors.reserve(r.poses);
  for (std::size_t i = 0; i < r.poses; ++i) {
    const Eigen::Vector3d aligned =
        r.alignment.scale * (r.alignment.transform.linear() * est_positions[i]) +
        r.alignment.transform.translation();
    errors.push_back((aligned - gt_positions[i]).norm());
  }
  r.rmse = rms(errors);
  r.mean = mean_of(errors);
  r.median = median_of(errors);
  r.max = *std::max_element(errors.begin(), errors.end());
  r.final_drift = errors.back();
  r.path_length = cumulative_distances(ground_truth).back();
  r.rmse_percent_of_path = r.path_length > 0.0 ? 100.0 * r.rmse / r.path_length : 0.0;
  return r;
}

RelativeErrors relative_errors(const std::vector<Pose>& ground_truth,
                               const std::vector<Pose>& estimate, std::size_t delta) {
  check_same_size(ground_truth, estimate, "RPE");
  if (delta == 0) fail("RPE", "frame delta must be at least 1");
  RelativeErrors errors;
  for (std::size_t i = 0; i + delta < ground_truth.size(); ++i)
    add_relative_error(ground_truth, estimate, i, i + delta, errors.translation, errors.rotation);
  return errors;
}

RpeResult compute_rpe_frames(const std::vector<Pose>& ground_truth,
                             const std::vector<Pose>& estimate, std::size_t delta) {
  const RelativeErrors errors = relative_errors(ground_truth, estimate, delta);
  return summarise_rpe(errors.translation, errors.rotation);
}

RpeResult compute_rpe_distance(const std::vector<Pose>& ground_truth,
                               const std::vector<Pose>& estimate, double distance) {
  check_same_size(ground_truth, estimate, "RPE");
  if (!(distance > 0.0)) fail("RPE", "distance delta must be positive");
  const std::vector<double> along = cumulative_distances(ground_truth);
  std::vector<double> translation, rotation;
  std::size_t j = 0;
  for (std::size_t i = 0; i < ground_truth.size(); ++i) {
    j = std::max(j, i + 1);
    while (j < along.size() && along[j] - along[i] < distance) ++j;
    if (j >= along.size()) break;
    add_relative_error(ground_truth, estimate, i, j, translation, rotation);
  }
  return summarise_rpe(translation, rotation);
}

KittiDriftResult compute_kitti_drift(const std::vector<Pose>& ground_truth,
                                     const std::vector<Pose>& estimate) {
  check_same_size(ground_truth, estimate, "KITTI drift");
  static constexpr double kLengths[] = {100, 200, 300, 400, 500, 600, 700, 800};
  constexpr std::size_t kStep = 10;  // the devkit evaluates a segment every 10 frames
  const std::vector<double> along = cumulative_distances(ground_truth);
  KittiDriftResult r;
  double translation_sum = 0.0, rotation_sum = 0.0;
  for (double length : kLengths) {
    bool used = false;
    for (std::size_t first = 0; first < ground_truth.size(); first += kStep) {
      // The devkit's last frame: the first one strictly beyond `length` along the path.
      const auto it = std::upper_bound(along.begin() + static_cast<std::ptrdiff_t>(first),
                                       along.end(), along[first] + length);
      if (it == along.end()) continue;
      const std::size_t last = static_cast<std::size_t>(it - along.begin());
      const Pose error = (estimate[first].inverse() * estimate[last]).inverse() *
                         (ground_truth[first].inverse() * ground_truth[last]);
      translation_sum += error.translation().norm() / length;
      rotation_sum += devkit_rotation_error(error) / length;
      ++r.segments;
      used = true;
    }
    if (used) r.lengths_used.push_back(length);
  }
  if (r.segments > 0) {
    r.translation_percent = 100.0 * translation_sum / static_cast<double>(r.segments);
    r.rotation_deg_per_100m = 100.0 * kRadToDeg * rotation_sum / static_cast<double>(r.segments);
  }
  return r;
}

Association associate(const Trajectory& ground_truth, const Trajectory& estimate,
                      bool allow_partial, double max_time_gap) {
  Association out;
  if (ground_truth.size() == 0) fail("ground truth", "has no poses");
  if (estimate.size() == 0) fail("estimate", "has no poses");
  if (ground_truth.has_timestamps() && estimate.has_timestamps()) {
    out.by_timestamp = true;
    std::size_t j = 0;
    for (std::size_t i = 0; i < estimate.size(); ++i) {
      const double t = estimate.timestamps[i];
      while (j + 1 < ground_truth.size() && std::abs(ground_truth.timestamps[j + 1] - t) <=
                                                std::abs(ground_truth.timestamps[j] - t))
        ++j;
      if (std::abs(ground_truth.timestamps[j] - t) > max_time_gap) continue;
      out.ground_truth.push_back(ground_truth.poses[j]);
      out.estimate.push_back(estimate.poses[i]);
      out.timestamps.push_back(t);
      out.estimate_index.push_back(i);
    }
    const std::size_t expected = std::min(ground_truth.size(), estimate.size());
    if (out.estimate.empty())
      fail("association", "no estimate timestamp is within " + std::to_string(max_time_gap) +
                              " s of a ground-truth timestamp");
    if (!allow_partial &&
        (out.estimate.size() != expected || ground_truth.size() != estimate.size()))
      fail("association", "matched " + std::to_string(out.estimate.size()) +
                              " poses by timestamp out of " + std::to_string(ground_truth.size()) +
                              " (ground truth) and " + std::to_string(estimate.size()) +
                              " (estimate); use --allow-partial to evaluate the matched ones");
    out.description = "by timestamp (" + std::to_string(out.estimate.size()) + " pairs within " +
                      std::to_string(max_time_gap) + " s)";
    return out;
  }
  if (ground_truth.size() != estimate.size() && !allow_partial)
    fail("association", "ground truth has " + std::to_string(ground_truth.size()) +
                            " poses and the estimate " + std::to_string(estimate.size()) +
                            "; use --allow-partial to evaluate the common prefix");
  const std::size_t n = std::min(ground_truth.size(), estimate.size());
  out.ground_truth.assign(ground_truth.poses.begin(),
                          ground_truth.poses.begin() + static_cast<std::ptrdiff_t>(n));
  out.estimate.assign(estimate.poses.begin(),
                      estimate.poses.begin() + static_cast<std::ptrdiff_t>(n));
  for (std::size_t i = 0; i < n; ++i) out.estimate_index.push_back(i);
  out.description =
      "by index (" + std::to_string(n) + " poses; " +
      (ground_truth.has_timestamps() || estimate.has_timestamps() ? "only one file has timestamps)"
                                                                  : "neither file has timestamps)");
  return out;
}

}  // namespace scanmatch
