#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <tuple>

#include "scanmatch/core/error.hpp"
#include "scanmatch/geometry/gaussian_voxel_map.hpp"
#include "scanmatch/geometry/voxel_filter.hpp"
#include "scanmatch/geometry/voxel_key.hpp"

using namespace scanmatch;

namespace {
PointCloud random_cloud(std::size_t n, float extent, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-extent, extent);
  PointCloud cloud;
  for (std::size_t i = 0; i < n; ++i) {
    cloud.points.emplace_back(u(rng), u(rng), u(rng));
    cloud.intensity.push_back(static_cast<float>(i % 7));
    cloud.ring.push_back(static_cast<std::uint16_t>(i % 16));
    cloud.time.push_back(static_cast<float>(i) * 1e-6f);
  }
  return cloud;
}

using Key = std::tuple<long, long, long>;
Key key_of(const Point& p, double voxel) {
  return {static_cast<long>(std::floor(p.x() / voxel)),
          static_cast<long>(std::floor(p.y() / voxel)),
          static_cast<long>(std::floor(p.z() / voxel))};
}
}  // namespace

TEST(VoxelFilter, CentroidMatchesBruteForceGrouping) {
  const double voxel = 0.5;
  const PointCloud cloud = random_cloud(5000, 3.0f, 1);
  std::map<Key, std::pair<Eigen::Vector3d, int>> groups;
  for (const Point& p : cloud.points) {
    auto& g = groups[key_of(p, voxel)];
    if (g.second == 0) g.first.setZero();
    g.first += p.cast<double>();
    ++g.second;
  }
  const PointCloud out = voxel_downsample(cloud, voxel);
  ASSERT_EQ(out.size(), groups.size());
  ASSERT_TRUE(out.fields_consistent());
  ASSERT_EQ(out.intensity.size(), out.size());
  for (const Point& c : out.points) {
    const auto it = groups.find(key_of(c, voxel));
    ASSERT_NE(it, groups.end());
    EXPECT_LT((c.cast<double>() - it->second.first / it->second.second).norm(), 1e-5);
  }
}

TEST(VoxelFilter, NearestToCentroidKeepsOriginalPointsOnePerVoxel) {
  const double voxel = 0.4;
  const PointCloud cloud = random_cloud(3000, 2.0f, 2);
  const PointCloud out = voxel_downsample(cloud, voxel, VoxelReduction::kNearestToCentroid);
  const PointCloud centroids = voxel_downsample(cloud, voxel);
  ASSERT_EQ(out.size(), centroids.size());
  std::map<Key, int> seen;
  for (std::size_t i = 0; i < out.size(); ++i) {
    EXPECT_EQ(++seen[key_of(out.points[i], voxel)], 1);
    // The kept point is one of the input points, with its own fields.
    bool found = false;
    for (std::size_t j = 0; j < cloud.size() && !found; ++j)
      found = cloud.points[j] == out.points[i] && cloud.ring[j] == out.ring[i] &&
              cloud.time[j] == out.time[i];
    EXPECT_TRUE(found);
  }
}

TEST(VoxelFilter, SkipsNonFiniteAndRejectsBadVoxelSize) {
  PointCloud cloud;
  cloud.points = {Point(0.1f, 0.1f, 0.1f), Point(std::nanf(""), 0, 0),
                  Point(std::numeric_limits<float>::infinity(), 0, 0), Point(0.2f, 0.2f, 0.2f)};
  const PointCloud out = voxel_downsample(cloud, 1.0);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_NEAR(out.points[0].x(), 0.15f, 1e-6f);
  EXPECT_THROW(voxel_downsample(cloud, 0.0), Error);
  EXPECT_THROW(voxel_downsample(cloud, -1.0), Error);
  EXPECT_THROW(voxel_downsample(cloud, std::nan("")), Error);
  EXPECT_TRUE(voxel_downsample(PointCloud{}, 1.0).empty());
}

TEST(VoxelFilter, NegativeCoordinatesUseFloorNotTruncation) {
  PointCloud cloud;
  cloud.points = {Point(-0.1f, 0, 0), Point(0.1f, 0, 0)};  // different voxels of size 1
  EXPECT_EQ(voxel_downsample(cloud, 1.0).size(), 2u);
}

TEST(VoxelFilter, RejectsCoordinatesBeyondVoxelIndexRange) {
  PointCloud cloud;
  cloud.points = {Point(1e9f, 0, 0)};
  EXPECT_THROW(voxel_downsample(cloud, 0.01), Error);
}

TEST(VoxelKey, FloorsTowardsMinusInfinityInEitherPrecision) {
  for (const double x : {-2.5, -2.0, -1e-9, 0.0, 1e-9, 0.999, 2.0, 1e9, -1e9})
    EXPECT_EQ(floor_to_int(x), static_cast<std::int32_t>(std::floor(x))) << x;
  for (const float x : {-2.5f, -2.0f, -1e-7f, 0.0f, 0.999f, 3.0f})
    EXPECT_EQ(floor_to_int(x), static_cast<std::int32_t>(std::floor(x))) << x;
  EXPECT_EQ(voxel_key_scaled(Eigen::Vector3f(-0.5f, 0.5f, -1.0f)), (VoxelKey{-1, 0, -1}));
}

TEST(VoxelKey, TheMapsDivideByTheVoxelSize) {
  // 0.3 / 0.1 rounds below 3, 0.3 * (1 / 0.1) to 3: the maps keep the division they always had.
  EXPECT_EQ(voxel_key(Eigen::Vector3d(0.3, -0.3, 0.7), 0.1), (VoxelKey{2, -3, 6}));
  GaussianVoxelMapOptions o;
  o.voxel_size = 0.1;
  const GaussianVoxelMap map(o);
  const Eigen::Vector3d p(0.3, -0.3, 0.7);
  EXPECT_EQ(map.index_of(p), voxel_key(p, 0.1));
}

TEST(VoxelKey, HashSpreadsNeighbouringVoxelsOverTheSlots) {
  // A 16^3 block of voxels into 4096 slots: x ^ y ^ z fills 16 of them, the classic 73856093
  // multiply-xor 1981, a well-mixed hash about 4096 (1 - 1/e) = 2589.
  std::set<std::size_t> slots;
  for (int x = -8; x < 8; ++x)
    for (int y = -8; y < 8; ++y)
      for (int z = -8; z < 8; ++z) slots.insert(VoxelKeyHash{}(VoxelKey{x, y, z}) & 4095u);
  EXPECT_GT(slots.size(), 2400u);
}

TEST(Crop, RangeBoxAndNonFinite) {
  PointCloud cloud;
  cloud.points = {Point(0.5f, 0, 0), Point(2, 0, 0), Point(0, 5, 0), Point(std::nanf(""), 0, 0)};
  cloud.intensity = {1, 2, 3, 4};
  const PointCloud ranged = crop_range(cloud, 1.0, 4.0);
  ASSERT_EQ(ranged.size(), 1u);
  EXPECT_EQ(ranged.intensity[0], 2.0f);
  const Eigen::AlignedBox3f box(Eigen::Vector3f(-1, -1, -1), Eigen::Vector3f(3, 1, 1));
  EXPECT_EQ(crop_box(cloud, box).size(), 2u);
  EXPECT_EQ(crop_box(cloud, box, false).size(), 2u);  // (0,5,0) and the NaN point
  PointCloud copy = cloud;
  EXPECT_EQ(remove_non_finite(copy), 1u);
  EXPECT_EQ(copy.size(), 3u);
  EXPECT_EQ(copy.intensity.size(), 3u);
  EXPECT_EQ(remove_non_finite(copy), 0u);
}
