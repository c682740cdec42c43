#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <optional>
#include <random>

#include "scanmatch/core/error.hpp"
#include "scanmatch/features/loam_features.hpp"
#include "scanmatch/geometry/covariance.hpp"
#include "scanmatch/geometry/gaussian_voxel_map.hpp"
#include "scanmatch/geometry/kdtree.hpp"
#include "scanmatch/geometry/point_grid2.hpp"
#include "scanmatch/geometry/voxel_filter.hpp"
#include "scanmatch/io/cloud_io.hpp"
#include "scanmatch/registration/methods.hpp"
#include "scanmatch/registration/solver.hpp"
#include "scanmatch/sim/simulator.hpp"
#include "test_helpers.hpp"

using namespace scanmatch;

namespace {
using scanmatch::testing::degrees;

struct Pair {
  PointCloud source, target;
  Pose truth;                     // T_target_source
  Pose guess = Pose::Identity();  // constant-velocity guess: the previous frame's motion
};

// Consecutive frames of a simulated moving sensor (no motion distortion: the registration, not
// deskewing, is under test), downsampled like an odometry front end does.
Pair simulated_pair(const std::string& preset, const std::string& sensor, std::size_t frame) {
  sim::SimOptions o;
  o.preset = preset;
  o.sensor = sensor;
  o.frames = frame + 2;
  o.motion_distortion = false;
  const sim::Simulator s(o);
  return {voxel_downsample(s.frame(frame + 1), 0.25), voxel_downsample(s.frame(frame), 0.25),
          s.pose(frame).inverse() * s.pose(frame + 1),
          frame > 0 ? s.pose(frame - 1).inverse() * s.pose(frame) : Pose::Identity()};
}

void expect_recovers(const Pair& pair, const std::string& method, double metres, double deg,
                     std::optional<Pose> initial = std::nullopt) {
  RegistrationOptions o;
  o.method = method;
  o.solver.max_iterations = 60;
  const RegistrationResult r =
      register_clouds(pair.source, pair.target, o, initial.value_or(pair.guess));
  const Pose error = pair.truth.inverse() * r.transform;
  EXPECT_LT(error.translation().norm(), metres) << method << ": " << r.summary();
  EXPECT_LT(degrees(rotation_angle(error)), deg) << method << ": " << r.summary();
}
}  // namespace

TEST(RobustKernel, WeightsAndCosts) {
  RobustKernel k;
  EXPECT_DOUBLE_EQ(k.weight(100.0), 1.0);
  k.scale = 0.5;
  k.type = KernelType::kHuber;
  EXPECT_DOUBLE_EQ(k.weight(0.1), 1.0);
  EXPECT_DOUBLE_EQ(k.weight(1.0), 0.5);  // c / |r| beyond the threshold
  k.type = KernelType::kCauchy;
  EXPECT_DOUBLE_EQ(k.weight(0.25), 0.5);
  k.type = KernelType::kTukey;
  EXPECT_DOUBLE_EQ(k.weight(0.25), 0.0);
  EXPECT_DOUBLE_EQ(k.weight(0.0), 1.0);
  k.type = KernelType::kGemanMcClure;
  EXPECT_DOUBLE_EQ(k.weight(0.25), 0.25);
  // The weight is rho'(s): check by finite differences for every kernel.
  for (auto type :
       {KernelType::kHuber, KernelType::kCauchy, KernelType::kTukey, KernelType::kGemanMcClure}) {
    k.type = type;
    for (double s : {0.01, 0.2, 0.6})
      EXPECT_NEAR((k.cost(s + 1e-7) - k.cost(s - 1e-7)) / 2e-7, k.weight(s), 1e-5);
  }
  EXPECT_THROW(parse_kernel("l1"), Error);
}

TEST(Solver, PointJacobianMatchesNumericalDerivative) {
  const Pose T = from_xyz_rpy(0.3, -1.0, 2.0, 0.2, -0.4, 1.1);
  const Eigen::Vector3d p(1.5, -0.7, 2.2);
  const Eigen::Matrix<double, 3, 6> J = point_jacobian(T, p);
  for (int k = 0; k < 6; ++k) {
    Vector6d d = Vector6d::Zero();
    d(k) = 1e-6;
    const Eigen::Vector3d numeric = ((T * se3_exp(d)) * p - (T * se3_exp(-d)) * p) / 2e-6;
    EXPECT_LT((numeric - J.col(k)).norm(), 1e-6) << "column " << k;
  }
}

namespace {

// Point-to-point with exact correspondences: source i is target i moved by truth^-1.
struct ExactPairs {
  const PointCloud& s;
  const PointCloud& t;
  std::size_t size() const { return s.size(); }
  bool linearize(const Pose& T, std::size_t i, LinearSystem& sys, const RobustKernel& k) const {
    const Eigen::Vector3d p = s.points[i].cast<double>();
    sys.add<3>(point_jacobian(T, p), T * p - t.points[i].cast<double>(),
               Eigen::Matrix3d::Identity(), k);
    return true;
  }
};

// 300 random points in a 10 m cube (`seed`), and the same points moved by truth^-1.
std::pair<PointCloud, PointCloud> exact_clouds(unsigned seed, const Pose& truth) {
  PointCloud target, source;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-5, 5);
  for (int i = 0; i < 300; ++i) target.points.emplace_back(u(rng), u(rng), u(rng));
  for (const Point& q : target.points)
    source.points.push_back((truth.inverse() * q.cast<double>()).cast<float>());
  return {source, target};
}

}  // namespace

TEST(Solver, ExactCorrespondencesConvergeImmediately) {
  // Exact correspondences and a small motion: Gauss-Newton lands on the truth.
  const Pose truth = from_xyz_rpy(0.05, -0.03, 0.02, 0.01, 0.02, -0.015);
  const auto [source, target] = exact_clouds(3, truth);
  const RegistrationResult r =
      optimize(ExactPairs{source, target}, Pose::Identity(), SolverOptions{});
  EXPECT_TRUE(r.converged);
  EXPECT_LE(r.iterations, 4);
  EXPECT_TRUE(r.transform.isApprox(truth, 1e-6));
}

TEST(Solver, ACallersStopEndsTheSolveWhereItSays) {
  // A large rotation takes Gauss-Newton several steps; a caller that knows where the descent
  // leads (as the coarse stage does for a start reaching another start's optimum) ends it there.
  const Pose truth = from_xyz_rpy(1.0, -0.5, 0.2, 0.3, -0.2, 0.9);
  const auto [source, target] = exact_clouds(5, truth);
  const ExactPairs factor{source, target};
  const RegistrationResult full = optimize(factor, Pose::Identity(), SolverOptions{});
  ASSERT_TRUE(full.converged);
  ASSERT_GE(full.iterations, 3);
  const auto near_truth = [&](const Pose& T) {
    const Pose d = truth.inverse() * T;
    return d.translation().norm() < 0.1 && rotation_angle(d) < 0.1;
  };
  int asked = 0;
  const RegistrationResult stopped =
      optimize(factor, Pose::Identity(), SolverOptions{}, [&](const Pose& T) {
        ++asked;
        return near_truth(T);
      });
  EXPECT_EQ(stopped.stop_reason, "stopped by the caller");
  EXPECT_FALSE(stopped.converged);
  EXPECT_TRUE(near_truth(stopped.transform));
  EXPECT_LT(stopped.iterations, full.iterations);
  EXPECT_EQ(asked, stopped.iterations);  // asked once per accepted step, and it ended at the first
}

TEST(Solver, CorridorInformationIsDegenerateAlongItsAxis) {
  // Two parallel walls and a floor along x: nothing constrains translation along x. (Walls and
  // floor do not touch: an L-shaped neighbourhood would give a normal along x.)
  PointCloud corridor;
  for (int i = 0; i <= 200; ++i) {
    const float x = -10.0f + 0.1f * static_cast<float>(i);
    for (int k = 0; k <= 20; ++k) {
      const float h = 0.1f * static_cast<float>(k);
      corridor.points.emplace_back(x, -1.25f, 0.5f + h);
      corridor.points.emplace_back(x, 1.25f, 0.5f + h);
      corridor.points.emplace_back(x, -1.0f + h, 0.0f);
    }
  }
  RegistrationOptions o;
  o.method = "point-to-plane";
  const RegistrationResult r = register_clouds(corridor, corridor, o);
  Eigen::SelfAdjointEigenSolver<Matrix6d> solver(r.information);
  const Vector6d weakest = solver.eigenvectors().col(0);
  EXPECT_GT(std::abs(weakest(3)), 0.99);  // the translation-x direction
  // Closing the corridor with an end wall removes the degeneracy.
  PointCloud closed = corridor;
  for (int j = 0; j <= 20; ++j)
    for (int k = 0; k <= 20; ++k)
      closed.points.emplace_back(10.5f, -1.0f + 0.1f * j, 0.5f + 0.1f * k);
  const RegistrationResult c = register_clouds(closed, closed, o);
  EXPECT_GT(r.condition_number, 1e8);
  EXPECT_LT(c.condition_number, 1e5);
}

TEST(Geometry, KdTreeMatchesBruteForce) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-10, 10);
  PointCloud cloud;
  for (int i = 0; i < 2000; ++i) cloud.points.emplace_back(u(rng), u(rng), u(rng));
  const KdTree tree(cloud.points);
  for (int q = 0; q < 100; ++q) {
    const Point query(u(rng), u(rng), u(rng));
    std::size_t best = 0;
    for (std::size_t i = 1; i < cloud.size(); ++i)
      if ((cloud.points[i] - query).squaredNorm() < (cloud.points[best] - query).squaredNorm())
        best = i;
    std::size_t index;
    float d2;
    ASSERT_TRUE(tree.nearest(query, 1e9f, index, d2));
    EXPECT_EQ(index, best);
    std::size_t indices[5];
    float distances[5];
    EXPECT_EQ(tree.knn(query, 5, indices, distances), 5u);
    EXPECT_EQ(indices[0], best);
    for (int k = 1; k < 5; ++k) EXPECT_LE(distances[k - 1], distances[k]);
  }
  std::size_t index;
  float d2;
  EXPECT_FALSE(tree.nearest(Point(100, 100, 100), 1.0f, index, d2));
}

TEST(Geometry, PointGrid2FindsWhatABruteForceSearchFinds) {
  // Clustered walls and scattered points, queries on and off the grid, radii from a few cm to
  // several cells: the nearest within the radius, exactly, and of equally near points the first.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-12, 12), small(-0.05, 0.05);
  std::vector<Eigen::Vector2d> points;
  for (int i = 0; i < 1500; ++i) points.emplace_back(u(rng), 3.0 + small(rng));  // a wall
  for (int i = 0; i < 500; ++i) points.emplace_back(u(rng), u(rng));
  points.push_back(points[10]);  // a duplicate: the first of the two is the answer
  points.emplace_back(std::nan(""), 1.0);
  points.emplace_back(1.0, std::numeric_limits<double>::infinity());
  const PointGrid2 grid(points, 0.2);
  EXPECT_EQ(grid.size(), points.size() - 2);  // the non-finite ones are not indexed
  const auto brute = [&](const Eigen::Vector2d& q, double max_squared) {
    std::optional<std::size_t> best;
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (!points[i].allFinite()) continue;
      const double d = (points[i] - q).squaredNorm();
      if (d <= max_squared && (!best || d < (points[*best] - q).squaredNorm())) best = i;
    }
    return best;
  };
  std::uniform_real_distribution<double> far(-20, 20);
  std::size_t found = 0;
  for (int q = 0; q < 3000; ++q) {
    const Eigen::Vector2d query(far(rng), q % 3 == 0 ? 3.0 + far(rng) * 0.02 : far(rng));
    for (const double radius : {0.05, 0.3, 1.2, 5.0, 40.0}) {
      const std::optional<std::size_t> expected = brute(query, radius * radius);
      std::size_t index = 0;
      double squared = -1.0;
      const bool hit = grid.nearest(query, radius * radius, index, squared);
      ASSERT_EQ(hit, expected.has_value()) << query.transpose() << " within " << radius;
      if (!hit) continue;
      ++found;
      EXPECT_EQ(index, *expected);
      EXPECT_EQ(squared, (points[index] - query).squaredNorm());
    }
  }
  EXPECT_GT(found, 3000u);  // the radii found something often, and missed often
  std::size_t index = 0;
  double squared = 0.0;
  ASSERT_TRUE(grid.nearest(points[10], 0.01, index, squared));
  EXPECT_EQ(index, 10u);
  EXPECT_EQ(squared, 0.0);
  EXPECT_FALSE(grid.nearest(Eigen::Vector2d(1e6, -1e6), 4.0, index, squared));
  // Far from every point, with a radius reaching them all (beyond the rings it looks at).
  ASSERT_TRUE(grid.nearest(Eigen::Vector2d(300.0, 300.0), 1e12, index, squared));
  EXPECT_EQ(index, *brute(Eigen::Vector2d(300.0, 300.0), 1e12));
  EXPECT_FALSE(grid.nearest(Eigen::Vector2d(std::nan(""), 0.0), 4.0, index, squared));

  // Full cells ruled out by their distance: a lattice with points on the cell edges, listed
  // twice (ties), queried on edges, corners and between them. Still the first of the nearest.
  std::vector<Eigen::Vector2d> lattice;
  for (int copy = 0; copy < 2; ++copy)
    for (int x = 0; x <= 40; ++x)
      for (int y = 0; y <= 40; ++y) lattice.emplace_back(0.05 * x, 0.05 * y);
  const PointGrid2 dense(lattice, 0.2);
  for (int qx = -4; qx <= 84; ++qx)
    for (int qy = -4; qy <= 84; qy += 7) {
      const Eigen::Vector2d query(0.025 * qx, 0.025 * qy);
      for (const double radius : {0.03, 0.3}) {
        std::optional<std::size_t> expected;
        for (std::size_t i = 0; i < lattice.size(); ++i) {
          const double d = (lattice[i] - query).squaredNorm();
          if (d <= radius * radius && (!expected || d < (lattice[*expected] - query).squaredNorm()))
            expected = i;
        }
        const bool hit = dense.nearest(query, radius * radius, index, squared);
        ASSERT_EQ(hit, expected.has_value()) << query.transpose() << " within " << radius;
        if (hit) {
          EXPECT_EQ(index, *expected) << query.transpose();
        }
      }
    }

  // A stray return kilometres away coarsens the cells, and the answers stay exact.
  std::vector<Eigen::Vector2d> stray = {{0.0, 0.0}, {0.3, 0.1}, {4e3, -3e3}};
  const PointGrid2 coarse(stray, 0.2);
  EXPECT_GT(coarse.cell(), 0.2);
  ASSERT_TRUE(coarse.nearest(Eigen::Vector2d(0.25, 0.0), 1.0, index, squared));
  EXPECT_EQ(index, 1u);
  ASSERT_TRUE(coarse.nearest(Eigen::Vector2d(4e3, -3e3 + 0.5), 1.0, index, squared));
  EXPECT_EQ(index, 2u);
  EXPECT_FALSE(PointGrid2({}, 0.2).nearest(Eigen::Vector2d::Zero(), 1.0, index, squared));
  // Points whose extent overflows a double still answer exactly.
  const PointGrid2 huge({{-1.7e308, 0.0}, {1.7e308, 0.0}, {1.0, 1.0}}, 0.2);
  ASSERT_TRUE(huge.nearest(Eigen::Vector2d(1.1, 1.0), 1.0, index, squared));
  EXPECT_EQ(index, 2u);
  EXPECT_FALSE(huge.nearest(Eigen::Vector2d(1e300, 1e300), 1.0, index, squared));
  EXPECT_THROW(PointGrid2(stray, 0.0), Error);
  EXPECT_THROW(PointGrid2(stray, std::nan("")), Error);
}

TEST(Geometry, KdTree2MatchesBruteForce) {
  // The same tree in 2D and double precision, as the 2D methods use it.
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> u(-10, 10);
  std::vector<Eigen::Vector2d> points;
  for (int i = 0; i < 1000; ++i) points.emplace_back(u(rng), u(rng));
  const KdTree2 tree(points);
  EXPECT_EQ(tree.size(), points.size());
  for (int q = 0; q < 100; ++q) {
    const Eigen::Vector2d query(u(rng), u(rng));
    std::size_t best = 0;
    for (std::size_t i = 1; i < points.size(); ++i)
      if ((points[i] - query).squaredNorm() < (points[best] - query).squaredNorm()) best = i;
    std::size_t index;
    double d2;
    ASSERT_TRUE(tree.nearest(query, 1e9, index, d2));
    EXPECT_EQ(index, best);
    EXPECT_DOUBLE_EQ(d2, (points[best] - query).squaredNorm());
    std::size_t indices[4];
    double distances[4];
    EXPECT_EQ(tree.knn(query, 4, indices, distances), 4u);
    EXPECT_EQ(indices[0], best);
    for (int k = 1; k < 4; ++k) EXPECT_LE(distances[k - 1], distances[k]);
  }
  std::size_t index;
  double d2;
  EXPECT_FALSE(tree.nearest(Eigen::Vector2d(100, 100), 1.0, index, d2));
}

TEST(Geometry, GaussianMapMergeEqualsBatchStatistics) {
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0.0, 0.1);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 50; ++i)
    points.emplace_back(0.5 + n(rng), 0.5 + 0.5 * n(rng), 0.5 + 0.2 * n(rng));
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : points) mean += p;
  mean /= 50.0;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& p : points) cov += (p - mean) * (p - mean).transpose();
  cov /= 50.0;
  // Insert in three batches of different sizes with the CTF rule (merge from 5 pending points).
  GaussianVoxelMapOptions options;
  options.voxel_size = 10.0;
  options.merge_threshold = 5;
  GaussianVoxelMap map(options);
  const auto batch = [&](int from, int to) {
    PointCloud c;
    for (int i = from; i < to; ++i)
      c.points.push_back(points[static_cast<std::size_t>(i)].cast<float>());
    return c;
  };
  EXPECT_EQ(map.insert(batch(0, 3)), 0u);  // 3 pending: below the 5-point rule, nothing merged
  EXPECT_EQ(map.find({0.5, 0.5, 0.5}), nullptr);
  EXPECT_EQ(map.insert(batch(3, 20)), 1u);
  EXPECT_EQ(map.insert(batch(20, 50)), 1u);
  const GaussianVoxel* v = map.find({0.5, 0.5, 0.5});
  ASSERT_NE(v, nullptr);
  EXPECT_EQ(v->count, 50u);
  EXPECT_LT((v->mean - mean).norm(), 1e-6);
  EXPECT_LT((v->covariance - cov).norm(), 1e-6);
  // The planar information has the smallest eigenvector as its stiff direction.
  const Eigen::Vector3d normal = v->normal;
  EXPECT_NEAR(normal.dot(planar_information(*v, options.planar_epsilon) * normal), 1e6, 1.0);
  EXPECT_EQ(map.remove_far(Eigen::Vector3d(100, 0, 0), 10.0), 1u);
  EXPECT_EQ(map.size(), 0u);
}

TEST(Registration, EveryMethodRecoversSimulatedMotion) {
  // Plane-based methods: 2 cm and 0.1 deg on consecutive frames (sensor noise is 2-3 cm per point,
  // averaged over thousands of points). Point-based methods (icp, point-to-line) match points that
  // are not the same surface samples (0.25 m voxel centroids of different scans), so they keep a
  // bias of up to a third of the voxel size at car speed: 12 cm and 0.6 deg.
  const Pair pairs[] = {simulated_pair("dynamic-indoor", "mid360", 30),
                        simulated_pair("campus-os1", "os1-64", 40),
                        simulated_pair("urban-hdl64", "hdl64", 20)};
  for (const Pair& pair : pairs) {
    for (const char* m : {"point-to-plane", "gicp", "vgicp", "ndt", "ctf-fine"})
      expect_recovers(pair, m, 0.02, 0.1);
    for (const char* m : {"icp", "icp-gn", "point-to-line"}) expect_recovers(pair, m, 0.12, 0.6);
  }
}

TEST(Registration, BruteForceIcpEqualsKdTreeIcp) {
  const Pair pair = simulated_pair("dynamic-indoor", "mid360", 10);
  Pair small{voxel_downsample(pair.source, 0.6), voxel_downsample(pair.target, 0.6), pair.truth};
  RegistrationOptions o;
  o.method = "icp-brute";
  const RegistrationResult brute = register_clouds(small.source, small.target, o);
  o.method = "icp-kdtree";
  const RegistrationResult tree = register_clouds(small.source, small.target, o);
  EXPECT_EQ(brute.iterations, tree.iterations);
  EXPECT_TRUE(brute.transform.isApprox(tree.transform, 1e-9));
}

TEST(Registration, ThreadedEqualsSingleThreaded) {
  const Pair pair = simulated_pair("dynamic-outdoor", "mid360", 5);
  RegistrationOptions o;
  o.method = "gicp";
  const RegistrationResult one = register_clouds(pair.source, pair.target, o);
  o.solver.num_threads = 2;
  const RegistrationResult two = register_clouds(pair.source, pair.target, o);
  EXPECT_LT((one.transform.translation() - two.transform.translation()).norm(), 1e-6);
}

TEST(Registration, RecoversFromAnOffsetInitialGuess) {
  const Pair pair = simulated_pair("dynamic-outdoor", "mid360", 50);
  const Pose initial = pair.truth * from_xyz_rpy(0.3, -0.2, 0.05, 0.01, -0.01, 0.05);
  // ctf-fine: 0.11 deg on this pair since the campus drives follow the roads (2026-11-26).
  for (const char* m : {"gicp", "vgicp", "ndt", "ctf-fine", "point-to-plane"})
    expect_recovers(pair, m, 0.02, 0.15, initial);
}

TEST(Registration, BadInputGivesClearErrors) {
  PointCloud few;
  few.points = {Point(0, 0, 0), Point(1, 0, 0)};
  const Pair pair = simulated_pair("dynamic-indoor", "mid360", 1);
  RegistrationOptions o;
  o.method = "gicp";
  EXPECT_THROW(register_clouds(few, pair.target, o), Error);
  o.method = "magic";
  EXPECT_THROW(register_clouds(pair.source, pair.target, o), Error);
  o.method = "icp";
  Pose bad = Pose::Identity();
  bad.translation().x() = std::nan("");
  EXPECT_THROW(register_clouds(pair.source, pair.target, o, bad), Error);
}

TEST(Registration, RealHdl32PairWithinFiveCentimetresAndHalfADegree) {
  const std::string folder = scanmatch::testing::shared_data("data/3d/hdl32_pair");
  if (folder.empty()) GTEST_SKIP() << "../shared/data/3d/hdl32_pair not present";
  const PointCloud source = voxel_downsample(read_cloud(folder + "/source.ply"), 0.1);
  const PointCloud target = voxel_downsample(read_cloud(folder + "/target.ply"), 0.1);
  Eigen::Matrix4d M;
  std::ifstream in(folder + "/T_target_source.txt");
  for (int i = 0; i < 16; ++i) in >> M(i / 4, i % 4);
  const Pair pair{source, target, from_matrix(M)};
  for (const char* m : {"point-to-plane", "gicp", "vgicp", "ndt", "ctf-fine"})
    expect_recovers(pair, m, 0.05, 0.5);
}

TEST(Cli, RegisterPrintsTransformAndRejectsBadInput) {
  scanmatch::testing::TempDir dir;
  const Pair pair = simulated_pair("dynamic-indoor", "mid360", 3);
  write_cloud(dir.file("s.pcd"), pair.source);
  write_cloud(dir.file("t.pcd"), pair.target);
  const auto ok = scanmatch::testing::run_cli("register " + dir.file("s.pcd") + " " +
                                              dir.file("t.pcd") + " --method ctf-fine --json");
  ASSERT_EQ(ok.status, 0) << ok.output;
  EXPECT_NE(ok.output.find("\"transform\""), std::string::npos);
  EXPECT_NE(ok.output.find("\"condition_number\""), std::string::npos);
  EXPECT_NE(
      scanmatch::testing::run_cli("register " + dir.file("s.pcd") + " " + dir.file("missing.pcd"))
          .status,
      0);
  EXPECT_NE(scanmatch::testing::run_cli("register " + dir.file("s.pcd") + " " + dir.file("t.pcd") +
                                        " --init 1,2,3")
                .status,
            0);
  PointCloud empty;
  write_cloud(dir.file("e.pcd"), empty);
  const auto e =
      scanmatch::testing::run_cli("register " + dir.file("e.pcd") + " " + dir.file("t.pcd"));
  EXPECT_NE(e.status, 0);
  EXPECT_NE(e.output.find("empty"), std::string::npos);
}

TEST(LoamFeatures, EdgesOnCornersPlanesOnWalls) {
  // A 16-ring scan of a 10 m x 6 m box room from its centre: edges must lie on the four vertical
  // corners, planar points on the walls away from them.
  PointCloud scan;
  for (int ring = 0; ring < 16; ++ring) {
    const double elevation = (-15.0 + 2.0 * ring) * M_PI / 180.0;
    for (int a = 0; a < 1024; ++a) {
      const double azimuth = 2 * M_PI * a / 1024.0;
      const Eigen::Vector3d d(std::cos(elevation) * std::cos(azimuth),
                              std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
      const double t =
          std::min(5.0 / std::max(std::abs(d.x()), 1e-9), 3.0 / std::max(std::abs(d.y()), 1e-9));
      scan.points.push_back((d * t).cast<float>());
      scan.ring.push_back(static_cast<std::uint16_t>(ring));
    }
  }
  const LoamFeatures f = extract_loam_features(scan);
  ASSERT_GT(f.edges.size(), 16u);
  ASSERT_GT(f.planes.size(), 100u);
  for (const Point& e : f.edges.points)
    EXPECT_LT(std::min(std::abs(std::abs(e.x()) - 5.0f), std::abs(std::abs(e.y()) - 3.0f)), 0.05f);
  std::size_t near_corner = 0;
  for (const Point& e : f.edges.points)
    near_corner +=
        std::abs(std::abs(e.x()) - 5.0f) < 0.2f && std::abs(std::abs(e.y()) - 3.0f) < 0.2f;
  EXPECT_GT(near_corner, f.edges.size() * 9 / 10);
  for (const Point& p : f.planes.points)
    EXPECT_FALSE(std::abs(std::abs(p.x()) - 5.0f) < 0.05f &&
                 std::abs(std::abs(p.y()) - 3.0f) < 0.05f);
  // Without the ring field, rings from elevation give the same rings.
  PointCloud no_ring;
  no_ring.points = scan.points;
  const auto rings = rings_from_elevation(no_ring, 16);
  EXPECT_EQ(rings, scan.ring);
}

TEST(Registration, LoamRecoversSimulatedMotion) {
  // Feature ICP sees ~2,000 features rather than tens of thousands of points: 5 cm and 0.3 deg
  // (combined), 5 cm and 0.6 deg for the single-residual variants; edges alone 10 cm (urban-hdl64
  // frame 41: 8.0 cm along the road since undistorted frames carry no point time, so each ring is
  // ordered by azimuth and its feature segments start behind the sensor; 682 edge pairs).
  for (const char* preset : {"campus-os1", "urban-hdl64"}) {
    SCOPED_TRACE(preset);
    sim::SimOptions o;
    o.preset = preset;
    o.frames = 42;
    o.motion_distortion = false;
    const sim::Simulator s(o);
    const Pair raw{s.frame(41), s.frame(40), s.pose(40).inverse() * s.pose(41),
                   s.pose(39).inverse() * s.pose(40)};
    expect_recovers(raw, "loam", 0.05, 0.3);
    expect_recovers(raw, "loam-edge", 0.10, 0.6);
    expect_recovers(raw, "loam-plane", 0.05, 0.6);
  }
}
