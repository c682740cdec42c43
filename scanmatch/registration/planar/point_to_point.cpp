#include "scanmatch/registration/planar/point_to_point.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>

#include "scanmatch/core/error.hpp"
#include "scanmatch/registration/planar/common.hpp"
#include "scanmatch/registration/planar/reference2d.hpp"

namespace scanmatch {

using Vec2 = Eigen::Vector2d;

Pose2 align_svd(const std::vector<Vec2>& from, const std::vector<Vec2>& to) {
  if (from.size() != to.size() || from.size() < 2)
    throw Error("align_svd: needs two or more pairs of points");
  const Vec2 mu_p = planar::centroid(from), mu_q = planar::centroid(to);
  Eigen::Matrix2d W = Eigen::Matrix2d::Zero();
  for (std::size_t i = 0; i < from.size(); ++i) W += (to[i] - mu_q) * (from[i] - mu_p).transpose();
  const Eigen::JacobiSVD<Eigen::Matrix2d> svd(W, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix2d U = svd.matrixU();
  const Eigen::Matrix2d V = svd.matrixV();
  if ((U * V.transpose()).determinant() < 0) U.col(1) *= -1;  // a reflection is not a rotation
  Pose2 T = Pose2::Identity();
  T.linear() = U * V.transpose();
  T.translation() = mu_q - T.linear() * mu_p;
  return T;
}

namespace planar {

Registration2DResult point_to_point_icp(const Scan2D& current, const Reference2D& prepared,
                                        const Registration2DOptions& o, const Pose2& initial,
                                        bool use_tree, const PairFilter& keep) {
  const Scan2D& reference = prepared.scan();
  const KdTree2* tree = use_tree ? &prepared.tree() : nullptr;
  const double max_squared = o.max_correspondence_distance * o.max_correspondence_distance;
  // The nearest reference point to p within the correspondence distance.
  const auto nearest = [&](const Vec2& p, std::size_t& index, double& squared) {
    if (tree) return tree->nearest(p, max_squared, index, squared);
    squared = std::numeric_limits<double>::infinity();
    for (std::size_t j = 0; j < reference.points.size(); ++j) {
      const double d = (reference.points[j] - p).squaredNorm();
      if (d < squared) {
        squared = d;
        index = j;
      }
    }
    return squared <= max_squared;
  };
  Registration2DResult r;
  r.transform = initial;
  PointPairs pairs;
  IterationCycle cycle;  // a pose met again: the rest repeats
  for (r.iterations = 1; r.iterations <= o.max_iterations; ++r.iterations) {
    pairs.clear();
    const Eigen::Matrix2d R = r.transform.linear();
    for (std::size_t i = 0; i < current.points.size(); ++i) {
      const Vec2 p = r.transform * current.points[i];
      std::size_t j = 0;
      double squared = 0.0;
      if (!nearest(p, j, squared)) continue;
      if (keep && !keep(i, j, R)) continue;
      pairs.from.push_back(current.points[i]);
      pairs.to.push_back(reference.points[j]);
      pairs.distance_sum += std::sqrt(squared);
    }
    r.pairs = pairs.from.size();
    if (r.pairs < 3) break;
    const Pose2 next = align_svd(pairs.from, pairs.to);
    const Pose2 step = next * r.transform.inverse();
    r.transform = next;
    r.error = pairs.distance_sum / static_cast<double>(r.pairs);
    if (small_step(step, o.tolerance)) {
      r.converged = true;
      break;
    }
    if (cycle.closes(r, o.max_iterations)) break;  // the limit's outcome, known
  }
  r.iterations = std::min(r.iterations, o.max_iterations);
  return r;
}

}  // namespace planar

// The icp and icp-kdtree lines of the method table (registration2d.cpp).
Registration2DResult run_icp(const Scan2D& current, const Reference2D& reference,
                             const Registration2DOptions& options, const Pose2& initial) {
  return planar::point_to_point_icp(current, reference, options, initial, false);
}
Registration2DResult run_icp_kdtree(const Scan2D& current, const Reference2D& reference,
                                    const Registration2DOptions& options, const Pose2& initial) {
  return planar::point_to_point_icp(current, reference, options, initial, true);
}

}  // namespace scanmatch
