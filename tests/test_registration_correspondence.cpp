#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "scanmatch/core/se3.hpp"
#include "scanmatch/geometry/kdtree.hpp"
#include "scanmatch/registration/factors/correspondence.hpp"

using namespace scanmatch;

namespace {

PointCloud random_cloud(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-5.0f, 5.0f);
  PointCloud cloud;
  for (std::size_t i = 0; i < n; ++i) cloud.points.emplace_back(u(rng), u(rng), u(rng));
  return cloud;
}

// Squared distances from x to every target point, ascending.
std::vector<float> sorted_squared_distances(const PointCloud& target, const Eigen::Vector3d& x) {
  std::vector<float> d;
  for (const Point& q : target.points) d.push_back((q - x.cast<float>()).squaredNorm());
  std::sort(d.begin(), d.end());
  return d;
}

}  // namespace

TEST(NearestTargetSearch, FindsTheKNearestClosestFirstAndGatesOnTheNearest) {
  const PointCloud source = random_cloud(300, 1), target = random_cloud(500, 2);
  const KdTree tree(target.points);
  const double max_distance = 0.6;
  const NearestTargetSearch search{source, target, tree, max_distance};
  EXPECT_EQ(search.size(), source.size());
  const Pose T = se3_exp((Vector6d() << 0.05, -0.02, 0.1, 0.3, -0.2, 0.1).finished());
  std::size_t accepted = 0;
  for (std::size_t i = 0; i < source.size(); ++i) {
    NearestTargets<4> near;
    const bool found = search.search(T, i, near);
    const Eigen::Vector3d p = source.points[i].cast<double>();
    EXPECT_EQ(near.p, p);
    EXPECT_EQ(near.x, T * p);
    ASSERT_EQ(near.count, 4u);
    const std::vector<float> expected = sorted_squared_distances(target, near.x);
    for (std::size_t k = 0; k < near.count; ++k)
      EXPECT_FLOAT_EQ((target.points[near.index[k]] - near.x.cast<float>()).squaredNorm(),
                      expected[k]);
    EXPECT_EQ(found, expected[0] <= max_distance * max_distance) << "point " << i;
    accepted += found;
  }
  // The gate does separate: some points have a correspondence, some not.
  EXPECT_GT(accepted, 0u);
  EXPECT_LT(accepted, source.size());
}

TEST(NearestTargetSearch, NeedsAsManyTargetPointsAsAsked) {
  PointCloud source, target;
  source.points = {Point(0, 0, 0)};
  target.points = {Point(0.1f, 0, 0), Point(0.2f, 0, 0)};
  const KdTree tree(target.points);
  const NearestTargetSearch search{source, target, tree, 1.0};
  NearestTargets<8> near;
  EXPECT_TRUE(search.search(Pose::Identity(), 0, near, 2));
  EXPECT_EQ(near.count, 2u);
  EXPECT_EQ(near.index[0], 0u);
  EXPECT_EQ(near.index[1], 1u);
  EXPECT_FALSE(search.search(Pose::Identity(), 0, near, 3));  // only two target points
  PointCloud empty;
  const KdTree empty_tree(empty.points);
  const NearestTargetSearch nothing{source, empty, empty_tree, 1.0};
  NearestTargets<1> none;
  EXPECT_FALSE(nothing.search(Pose::Identity(), 0, none));
  EXPECT_EQ(none.count, 0u);
}
