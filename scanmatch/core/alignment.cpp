#include "scanmatch/core/alignment.hpp"

#include <Eigen/SVD>

#include "scanmatch/core/error.hpp"

namespace scanmatch {

Similarity umeyama_alignment(const std::vector<Eigen::Vector3d>& from,
                             const std::vector<Eigen::Vector3d>& to, bool with_scale) {
  if (from.size() != to.size() || from.empty())
    fail("umeyama_alignment", "needs equal, non-empty point sets");
  const double n = static_cast<double>(from.size());
  Eigen::Vector3d mean_from = Eigen::Vector3d::Zero(), mean_to = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < from.size(); ++i) {
    mean_from += from[i];
    mean_to += to[i];
  }
  mean_from /= n;
  mean_to /= n;
  Eigen::Matrix3d sigma = Eigen::Matrix3d::Zero();
  double variance_from = 0.0;
  for (std::size_t i = 0; i < from.size(); ++i) {
    const Eigen::Vector3d a = from[i] - mean_from, b = to[i] - mean_to;
    sigma += b * a.transpose();
    variance_from += a.squaredNorm();
  }
  sigma /= n;
  variance_from /= n;
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(sigma, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) S(2, 2) = -1.0;
  Similarity out;
  out.transform.linear() = svd.matrixU() * S * svd.matrixV().transpose();
  if (with_scale && variance_from > 0.0)
    out.scale = (svd.singularValues().asDiagonal() * S).trace() / variance_from;
  out.transform.translation() = mean_to - out.scale * out.transform.linear() * mean_from;
  return out;
}

}  // namespace scanmatch
