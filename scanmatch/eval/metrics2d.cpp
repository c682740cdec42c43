#include "scanmatch/eval/metrics2d.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>

#include "scanmatch/core/error.hpp"
#include "scanmatch/eval/metrics.hpp"
#include "scanmatch/registration/planar/line_fitting.hpp"

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

RevisitConsistency2D revisit_consistency_2d(const std::vector<Scan2D>& scans,
                                            const std::vector<Pose2>& poses,
                                            std::size_t revisit_gap, double max_distance,
                                            std::size_t max_queries) {
  if (scans.size() != poses.size())
    throw Error("revisit consistency: " + std::to_string(poses.size()) + " poses for " +
                std::to_string(scans.size()) + " scans");
  if (revisit_gap == 0) throw Error("revisit consistency: the revisit gap must be at least 1");
  if (!(max_distance > 0.0))
    throw Error("revisit consistency: the maximum distance must be positive");
  constexpr double kFarthestCell = 1e9;  // keeps cell indices inside int
  std::vector<Eigen::Vector2d> world;
  std::vector<std::size_t> scan_of, index_in_scan;
  for (std::size_t i = 0; i < scans.size(); ++i)
    for (std::size_t k = 0; k < scans[i].points.size(); ++k) {
      // A run that diverged can put points anywhere: those beyond any map are left out.
      const Eigen::Vector2d w = poses[i] * scans[i].points[k];
      if (!w.allFinite() || w.cwiseAbs().maxCoeff() / max_distance > kFarthestCell) continue;
      world.push_back(w);
      scan_of.push_back(i);
      index_in_scan.push_back(k);
    }
  RevisitConsistency2D out;
  if (world.empty()) return out;
  const std::size_t limit = std::max<std::size_t>(max_queries, 1);
  const std::size_t stride = std::max<std::size_t>(1, (world.size() + limit - 1) / limit);
  const std::size_t queries = (world.size() + stride - 1) / stride;
  // Cells as wide as the distance: the nearest other visit's point within it lies in the query's
  // cell or one of the eight around. (A k-d tree's nearest points are mostly the query's own
  // visit where the sensor moved slowly.)
  const auto cell_of = [&](const Eigen::Vector2d& p) {
    return Eigen::Vector2i(static_cast<int>(std::floor(p.x() / max_distance)),
                           static_cast<int>(std::floor(p.y() / max_distance)));
  };
  const auto key = [](const Eigen::Vector2i& c) {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(c.x())) << 32) |
           static_cast<std::uint32_t>(c.y());
  };
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> cells;
  for (std::size_t j = 0; j < world.size(); ++j) cells[key(cell_of(world[j]))].push_back(j);
  // As the fine stage's fit check measures a point (surface_distance): to the other visit's
  // surface, the segments to its beam neighbours, or beyond a surface's end to the end itself.
  constexpr double kMaxSegment = 0.3;  // longer segments span a gap, not a surface
  const auto surface_distance = [&](std::size_t i, std::size_t j, double squared) {
    const std::size_t b = scan_of[j];
    const Eigen::Vector2d local = poses[b].inverse() * world[i];
    const auto projected =
        project_onto_neighbour_segments(scans[b], index_in_scan[j], local, kMaxSegment);
    return projected ? (projected->point - local).norm() : std::sqrt(squared);
  };
  std::vector<double> distance(queries, std::numeric_limits<double>::quiet_NaN());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, queries), [&](const auto& range) {
    for (std::size_t q = range.begin(); q < range.end(); ++q) {
      const std::size_t i = q * stride;
      const Eigen::Vector2i c = cell_of(world[i]);
      double best = max_distance * max_distance;
      std::size_t nearest = world.size();
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy) {
          const auto it = cells.find(key(c + Eigen::Vector2i(dx, dy)));
          if (it == cells.end()) continue;
          // A cell lists its points by scan: the query's own visit (within revisit_gap scans) is
          // one stretch of it, skipped whole (most of a cell where the sensor moved slowly).
          const std::vector<std::size_t>& in_cell = it->second;
          const std::size_t a = scan_of[i];
          const auto own_begin =
              std::partition_point(in_cell.begin(), in_cell.end(),
                                   [&](std::size_t j) { return scan_of[j] + revisit_gap <= a; });
          const auto own_end = std::partition_point(own_begin, in_cell.end(), [&](std::size_t j) {
            return scan_of[j] < a + revisit_gap;
          });
          const auto visit = [&](auto begin, auto end) {
            for (auto j = begin; j != end; ++j) {
              const double d = (world[*j] - world[i]).squaredNorm();
              if (d <= best) {
                best = d;
                nearest = *j;
              }
            }
          };
          visit(in_cell.begin(), own_begin);
          visit(own_end, in_cell.end());
        }
      if (nearest < world.size())
        distance[q] = std::min(surface_distance(i, nearest, best), max_distance);
    }
  });
  out.points = queries;
  std::vector<double> revisited;
  for (double d : distance)
    if (std::isfinite(d)) revisited.push_back(d);
  out.revisited = revisited.size();
  if (revisited.empty()) return out;
  out.mean = mean_of(revisited);
  out.median = median_of(revisited);
  std::sort(revisited.begin(), revisited.end());
  out.p90 = revisited[std::min(
      revisited.size() - 1, static_cast<std::size_t>(0.9 * static_cast<double>(revisited.size())))];
  return out;
}

}  // namespace scanmatch
