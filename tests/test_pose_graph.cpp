// Pose graphs (scanmatch/mapping/pose_graph.hpp): loops around a known square path with noisy
// odometry (fixed seeds), where the truth is known, so drift before and after the solve is measured
// against it; wrong loop edges; the gauge; residual conventions; bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <tuple>
#include <vector>

#include "scanmatch/core/error.hpp"
#include "scanmatch/core/stopwatch.hpp"
#include "scanmatch/mapping/pose_graph.hpp"
#include "scanmatch/sim/random.hpp"

using namespace scanmatch;

namespace {

constexpr int kNodesPerLap = 40;  // 10 m square, 1 m steps, a 90 degree turn every 10 steps

// Noise of the simulated measurements, and the information matrices that state it.
constexpr double kOdometrySigmaXY = 0.02, kOdometrySigmaTheta = 0.005;  // m, rad per step
// A systematic yaw drift per step (like an odometry that under-reads its turns), on top of the
// noise: it makes the chained odometry drift far, and consistent loops can remove it.
constexpr double kOdometryYawBias = 0.005;  // rad per step
constexpr double kLoopSigmaXY = 0.02, kLoopSigmaTheta = 0.005;
constexpr double kOdometrySigmaRotation3D = 0.005;  // rad per axis per step

Eigen::Matrix3d information2d(double sigma_xy, double sigma_theta) {
  return Eigen::Vector3d(1 / (sigma_xy * sigma_xy), 1 / (sigma_xy * sigma_xy),
                         1 / (sigma_theta * sigma_theta))
      .asDiagonal();
}

Matrix6d information3d(double sigma_translation, double sigma_rotation) {
  Vector6d diagonal;
  diagonal << Eigen::Vector3d::Constant(1 / (sigma_translation * sigma_translation)),
      Eigen::Vector3d::Constant(1 / (sigma_rotation * sigma_rotation));
  return diagonal.asDiagonal();
}

// True poses of `count` nodes around the square, starting at the origin heading along x.
std::vector<Pose2> square_truth_2d(int count) {
  std::vector<Pose2> truth = {Pose2::Identity()};
  for (int k = 1; k < count; ++k) {
    const double turn = k % 10 == 0 ? M_PI / 2 : 0.0;
    truth.push_back(truth.back() * pose2(1.0, 0.0, turn));
  }
  return truth;
}

// The same square in 3D with a wavy height and a gentle roll and pitch.
std::vector<Pose> square_truth_3d(int count) {
  const std::vector<Pose2> planar = square_truth_2d(count);
  std::vector<Pose> truth;
  for (int k = 0; k < count; ++k) {
    const double phase = 2 * M_PI * k / kNodesPerLap;
    truth.push_back(from_xyz_rpy(planar[k].translation().x(), planar[k].translation().y(),
                                 0.5 * std::sin(phase), 0.1 * std::sin(phase),
                                 0.05 * std::sin(2 * phase), pose2_angle(planar[k])));
  }
  return truth;
}

Pose2 noise2d(sim::Rng& rng, double sigma_xy, double sigma_theta) {
  return pose2(sigma_xy * rng.normal(), sigma_xy * rng.normal(), sigma_theta * rng.normal());
}

Pose noise3d(sim::Rng& rng, double sigma_translation, double sigma_rotation) {
  Vector6d xi;  // se3_exp order: rotation, translation
  for (int i = 0; i < 6; ++i) xi[i] = (i < 3 ? sigma_rotation : sigma_translation) * rng.normal();
  return se3_exp(xi);
}

template <class PoseType>
double max_position_error(const std::vector<PoseType>& estimate,
                          const std::vector<PoseType>& truth) {
  double worst = 0.0;
  for (std::size_t i = 0; i < truth.size(); ++i)
    worst = std::max(worst, (estimate[i].translation() - truth[i].translation()).norm());
  return worst;
}

// A square graph: nodes at the chained noisy odometry, odometry edges, then true loop edges
// (noisy) between the nodes of each pair in `loops`.
struct Square2D {
  std::vector<Pose2> truth, odometry;
  PoseGraph2D graph;

  Square2D(int count, const std::vector<std::pair<int, int>>& loops, const PoseGraphConfig& config,
           std::uint64_t seed = 7)
      : truth(square_truth_2d(count)), graph(config) {
    sim::Rng rng(seed);
    odometry = {truth[0]};
    graph.add_node(truth[0]);
    for (int k = 1; k < count; ++k) {
      const Pose2 measured = truth[k - 1].inverse() * truth[k] *
                             noise2d(rng, kOdometrySigmaXY, kOdometrySigmaTheta) *
                             pose2(0, 0, kOdometryYawBias);
      odometry.push_back(odometry.back() * measured);
      graph.add_node(odometry.back());
      graph.add_edge(k - 1, k, measured, information2d(kOdometrySigmaXY, kOdometrySigmaTheta),
                     EdgeKind::kOdometry);
    }
    for (const auto& [from, to] : loops)
      add_loop(from, to,
               truth[from].inverse() * truth[to] * noise2d(rng, kLoopSigmaXY, kLoopSigmaTheta));
  }
  std::size_t add_loop(int from, int to, const Pose2& measured) {
    return graph.add_edge(from, to, measured, information2d(kLoopSigmaXY, kLoopSigmaTheta),
                          EdgeKind::kLoop);
  }
};

struct Square3D {
  std::vector<Pose> truth, odometry;
  PoseGraph3D graph;

  Square3D(int count, const std::vector<std::pair<int, int>>& loops, const PoseGraphConfig& config,
           std::uint64_t seed = 11)
      : truth(square_truth_3d(count)), graph(config) {
    sim::Rng rng(seed);
    odometry = {truth[0]};
    graph.add_node(truth[0]);
    for (int k = 1; k < count; ++k) {
      const Pose measured = truth[k - 1].inverse() * truth[k] *
                            noise3d(rng, kOdometrySigmaXY, kOdometrySigmaRotation3D) *
                            from_xyz_rpy(0, 0, 0, 0, 0, kOdometryYawBias);
      odometry.push_back(odometry.back() * measured);
      graph.add_node(odometry.back());
      graph.add_edge(k - 1, k, measured, information3d(kOdometrySigmaXY, kOdometrySigmaRotation3D),
                     EdgeKind::kOdometry);
    }
    for (const auto& [from, to] : loops)
      add_loop(from, to,
               truth[from].inverse() * truth[to] * noise3d(rng, kLoopSigmaXY, kLoopSigmaTheta));
  }
  std::size_t add_loop(int from, int to, const Pose& measured) {
    return graph.add_edge(from, to, measured, information3d(kLoopSigmaXY, kLoopSigmaTheta),
                          EdgeKind::kLoop);
  }
};

// Three laps of the square; from the second lap on, each corner sees the first lap's corner, and
// the last node sees the first.
constexpr int kSquareNodes = 3 * kNodesPerLap;
std::vector<std::pair<int, int>> corner_loops(int count) {
  std::vector<std::pair<int, int>> loops;
  for (int k = kNodesPerLap; k < count; k += 10) loops.push_back({k, k % kNodesPerLap});
  loops.push_back({count - 1, 0});
  return loops;
}
const std::vector<std::pair<int, int>> kTrueLoops = corner_loops(kSquareNodes);

PoseGraphConfig without_kernel() {
  PoseGraphConfig config;
  config.loop_kernel = LoopKernel::kNone;
  return config;
}

}  // namespace

TEST(PoseGraph2D, ResidualFollowsTheDocumentedConvention) {
  PoseGraph2D graph;
  graph.add_node(pose2(0, 0, 3.1));
  graph.add_node(pose2(0, 0, -3.1));
  graph.add_node(pose2(2, 1, 0));
  // Heading error wraps: -3.1 - 3.1 = -6.2 rad is 2 pi - 6.2 = 0.083 rad.
  graph.add_edge(0, 1, Pose2::Identity(), Eigen::Matrix3d::Identity(), EdgeKind::kOdometry);
  EXPECT_NEAR(graph.whitened_residual(0).z(), 2 * M_PI - 6.2, 1e-12);
  EXPECT_NEAR(graph.whitened_residual(0).head<2>().norm(), 0.0, 1e-12);
  // Node 2 seen from node 0 (heading 3.1) is at R(-3.1) (2, 1); the translation error is in the
  // measurement's frame (R_meas^T), then whitened by the Cholesky factor of the information.
  const Pose2 measurement = pose2(0.5, 0, M_PI / 2);
  const Eigen::Vector3d information_diagonal(4, 9, 1);
  graph.add_edge(0, 2, measurement, information_diagonal.asDiagonal(), EdgeKind::kLoop);
  const Eigen::Vector2d t_rel = Eigen::Rotation2Dd(-3.1) * Eigen::Vector2d(2, 1);
  const Eigen::Vector2d t_error = Eigen::Rotation2Dd(-M_PI / 2) * (t_rel - Eigen::Vector2d(0.5, 0));
  const double angle_error = std::remainder(-3.1 - M_PI / 2, 2 * M_PI);
  const Eigen::Vector3d expected(2 * t_error.x(), 3 * t_error.y(), angle_error);
  EXPECT_LT((graph.whitened_residual(1) - expected).norm(), 1e-12);
}

TEST(PoseGraph3D, ResidualFollowsTheDocumentedConvention) {
  PoseGraph3D graph;
  graph.add_node(Pose::Identity());
  graph.add_node(from_xyz_rpy(1, 0, 0, 0, 0, 0.1));
  graph.add_edge(0, 1, Pose::Identity(), Matrix6d::Identity(), EdgeKind::kOdometry);
  Vector6d expected;  // translation first, then 2 vec(q): rotation of 0.1 rad about z
  expected << 1, 0, 0, 0, 0, 2 * std::sin(0.05);
  EXPECT_LT((graph.whitened_residual(0) - expected).norm(), 1e-12);
}

TEST(PoseGraph2D, SquareLoopCutsDriftFiveFold) {
  Square2D square(kSquareNodes, kTrueLoops, PoseGraphConfig{});
  const double drift = max_position_error(square.odometry, square.truth);
  const PoseGraphSummary summary = square.graph.optimize();
  const double error = max_position_error(square.graph.poses(), square.truth);
  std::printf(
      "2D square: max position error %.3f m (odometry) -> %.3f m (graph), %d iterations, "
      "cost %.1f -> %.3f, %.2f ms\n",
      drift, error, summary.iterations, summary.initial_cost, summary.final_cost, summary.solve_ms);
  EXPECT_GT(drift, 0.5);  // the odometry really drifts
  EXPECT_LT(error, drift / 5);
  EXPECT_TRUE(summary.converged);
  EXPECT_TRUE(summary.outlier_edges.empty());
  EXPECT_EQ(summary.solves, 1);
  EXPECT_LT(summary.final_cost, summary.initial_cost);
}

TEST(PoseGraph2D, WrongLoopIsRejectedAndTheKernelMatters) {
  // Reference: the same graph without the wrong edge.
  Square2D clean(kSquareNodes, kTrueLoops, PoseGraphConfig{});
  clean.graph.optimize();
  const double clean_error = max_position_error(clean.graph.poses(), clean.truth);

  // Nodes 10 and 30 are opposite corners, 14 m apart; the wrong loop says they coincide.
  auto with_wrong_loop = [&](const PoseGraphConfig& config, std::size_t& wrong_edge) {
    Square2D square(kSquareNodes, kTrueLoops, config);
    wrong_edge = square.add_loop(10, 30, Pose2::Identity());
    const PoseGraphSummary summary = square.graph.optimize();
    return std::make_tuple(summary, square.graph.poses(),
                           max_position_error(square.graph.poses(), square.truth));
  };

  std::size_t wrong = 0;
  const auto [summary, poses, error] = with_wrong_loop(PoseGraphConfig{}, wrong);
  ASSERT_EQ(summary.outlier_edges, std::vector<std::size_t>{wrong});
  EXPECT_EQ(summary.solves, 2);
  // Re-solved without it from the same start: the clean graph's answer.
  EXPECT_LT(max_position_error(poses, clean.graph.poses()), 1e-6);

  // The kernel alone (no re-solve) already keeps the map close to the truth...
  PoseGraphConfig kernel_only;
  kernel_only.drop_outliers = false;
  const auto [kernel_summary, kernel_poses, kernel_error] = with_wrong_loop(kernel_only, wrong);
  EXPECT_EQ(kernel_summary.outlier_edges, std::vector<std::size_t>{wrong});
  EXPECT_EQ(kernel_summary.solves, 1);
  EXPECT_LT(kernel_error, clean_error + 0.05);

  // ...and plain least squares lets the wrong loop fold it.
  PoseGraphConfig plain = without_kernel();
  plain.drop_outliers = false;
  const auto [plain_summary, plain_poses, plain_error] = with_wrong_loop(plain, wrong);
  std::printf(
      "2D wrong loop: max position error %.3f m clean, %.3f m rejected, %.3f m Cauchy "
      "kept, %.3f m least squares; least squares flags %zu loops\n",
      clean_error, error, kernel_error, plain_error, plain_summary.outlier_edges.size());
  EXPECT_GT(plain_error, 1.0);
  EXPECT_GT(plain_error, 5 * kernel_error);
}

TEST(PoseGraph2D, OdometryKernelLetsLoopsOverruleAFailedScanMatch) {
  // A scan match that converged 2 m and 20 degrees off between nodes 49 and 50 (as a second
  // odometry edge beside the true one, so that the graph stays connected either way).
  auto with_failed_match = [](const PoseGraphConfig& config) {
    Square2D square(kSquareNodes, kTrueLoops, config);
    const Pose2 failed = square.truth[49].inverse() * square.truth[50] * pose2(2.0, 0.0, 0.35);
    square.graph.add_edge(49, 50, failed, information2d(kOdometrySigmaXY, kOdometrySigmaTheta),
                          EdgeKind::kOdometry);
    square.graph.optimize();
    return max_position_error(square.graph.poses(), square.truth);
  };
  Square2D clean(kSquareNodes, kTrueLoops, PoseGraphConfig{});
  clean.graph.optimize();
  const double clean_error = max_position_error(clean.graph.poses(), clean.truth);
  PoseGraphConfig robust;
  robust.odometry_kernel = LoopKernel::kCauchy;
  const double trusted = with_failed_match(PoseGraphConfig{});
  const double overruled = with_failed_match(robust);
  std::printf(
      "2D failed scan match: max position error %.3f m clean, %.3f m trusted, %.3f m "
      "with the odometry kernel\n",
      clean_error, trusted, overruled);
  EXPECT_GT(trusted, 0.3);
  EXPECT_LT(overruled, clean_error + 0.05);
}

TEST(PoseGraph3D, LoopWithRotationNoiseCutsDriftFiveFold) {
  Square3D square(kSquareNodes, kTrueLoops, PoseGraphConfig{});
  const double drift = max_position_error(square.odometry, square.truth);
  const PoseGraphSummary summary = square.graph.optimize();
  const double error = max_position_error(square.graph.poses(), square.truth);
  double rotation_drift = 0.0, rotation_error = 0.0;  // rad
  for (int k = 0; k < kSquareNodes; ++k) {
    rotation_drift =
        std::max(rotation_drift, rotation_angle(square.odometry[k].inverse() * square.truth[k]));
    rotation_error =
        std::max(rotation_error, rotation_angle(square.graph.pose(k).inverse() * square.truth[k]));
  }
  std::printf(
      "3D square: max position error %.3f m -> %.3f m, rotation %.2f -> %.2f deg, %d "
      "iterations, %.2f ms\n",
      drift, error, rotation_drift * kDegreesPerRadian, rotation_error * kDegreesPerRadian,
      summary.iterations, summary.solve_ms);
  EXPECT_GT(drift, 0.5);
  EXPECT_LT(error, drift / 5);
  EXPECT_LT(rotation_error, rotation_drift / 2);
  EXPECT_TRUE(summary.converged);
  EXPECT_TRUE(summary.outlier_edges.empty());
  // The quaternions stay unit: poses are rigid.
  for (const Pose& T : square.graph.poses()) EXPECT_TRUE(is_valid_pose(T.matrix(), 1e-9));
}

TEST(PoseGraph3D, WrongLoopIsRejectedAndTheKernelMatters) {
  Square3D clean(kSquareNodes, kTrueLoops, PoseGraphConfig{});
  clean.graph.optimize();
  const double clean_error = max_position_error(clean.graph.poses(), clean.truth);

  auto with_wrong_loop = [&](const PoseGraphConfig& config, std::size_t& wrong_edge) {
    Square3D square(kSquareNodes, kTrueLoops, config);
    wrong_edge = square.add_loop(10, 30, Pose::Identity());
    const PoseGraphSummary summary = square.graph.optimize();
    return std::make_pair(summary, max_position_error(square.graph.poses(), square.truth));
  };

  std::size_t wrong = 0;
  const auto [summary, error] = with_wrong_loop(PoseGraphConfig{}, wrong);
  ASSERT_EQ(summary.outlier_edges, std::vector<std::size_t>{wrong});
  EXPECT_NEAR(error, clean_error, 1e-6);

  PoseGraphConfig kernel_only;
  kernel_only.drop_outliers = false;
  const auto [kernel_summary, kernel_error] = with_wrong_loop(kernel_only, wrong);
  EXPECT_EQ(kernel_summary.outlier_edges, std::vector<std::size_t>{wrong});
  EXPECT_LT(kernel_error, clean_error + 0.05);

  PoseGraphConfig plain = without_kernel();
  plain.drop_outliers = false;
  const double plain_error = with_wrong_loop(plain, wrong).second;
  std::printf(
      "3D wrong loop: max position error %.3f m clean, %.3f m rejected, %.3f m Cauchy "
      "kept, %.3f m least squares\n",
      clean_error, error, kernel_error, plain_error);
  EXPECT_GT(plain_error, 1.0);
  EXPECT_GT(plain_error, 5 * kernel_error);
}

TEST(PoseGraph, FirstNodeStaysFixed) {
  // Start the graph away from the origin: node 0 must not move, whatever the loops pull.
  const Pose2 start2 = pose2(3, -2, 0.7);
  Square2D square2(kSquareNodes, kTrueLoops, PoseGraphConfig{});
  PoseGraph2D moved2;
  for (const Pose2& T : square2.graph.poses()) moved2.add_node(start2 * T);
  for (const auto& e : square2.graph.edges())
    moved2.add_edge(e.from, e.to, e.measurement, e.information, e.kind);
  moved2.optimize();
  EXPECT_EQ(moved2.pose(0).matrix(), start2.matrix());
  // The rest is the same solution, carried by the fixed first node.
  square2.graph.optimize();
  for (std::size_t i = 0; i < moved2.node_count(); ++i) {
    const Pose2 expected = start2 * square2.graph.pose(i);
    EXPECT_LT((moved2.pose(i).translation() - expected.translation()).norm(), 1e-6);
  }

  const Pose start3 = from_xyz_rpy(1, 2, 3, 0.1, -0.2, 0.3);
  Square3D square3(kSquareNodes, kTrueLoops, PoseGraphConfig{});
  PoseGraph3D moved3;
  for (const Pose& T : square3.graph.poses()) moved3.add_node(start3 * T);
  for (const auto& e : square3.graph.edges())
    moved3.add_edge(e.from, e.to, e.measurement, e.information, e.kind);
  const Pose before = moved3.pose(0);
  moved3.optimize();
  EXPECT_LT((moved3.pose(0).matrix() - before.matrix()).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(PoseGraph, OdometryOnlyKeepsTheChainedPoses) {
  Square2D square2(kNodesPerLap, {}, PoseGraphConfig{});
  const PoseGraphSummary summary2 = square2.graph.optimize();
  EXPECT_LT(summary2.initial_cost, 1e-18);
  EXPECT_LT(max_position_error(square2.graph.poses(), square2.odometry), 1e-9);
  for (int k = 0; k < kNodesPerLap; ++k)
    EXPECT_NEAR(
        std::remainder(pose2_angle(square2.graph.pose(k)) - pose2_angle(square2.odometry[k]),
                       2 * M_PI),
        0.0, 1e-9);

  Square3D square3(kNodesPerLap, {}, PoseGraphConfig{});
  square3.graph.optimize();
  for (int k = 0; k < kNodesPerLap; ++k)
    EXPECT_LT((square3.graph.pose(k).matrix() - square3.odometry[k].matrix()).cwiseAbs().maxCoeff(),
              1e-9);

  // No edges at all: nothing to solve, nothing moves.
  PoseGraph2D lonely;
  lonely.add_node(pose2(1, 2, 3));
  lonely.add_node(pose2(4, 5, 6));
  const PoseGraphSummary summary = lonely.optimize();
  EXPECT_EQ(summary.solves, 0);
  EXPECT_EQ(lonely.pose(1).matrix(), pose2(4, 5, 6).matrix());
}

TEST(PoseGraph, BadInputThrows) {
  auto expect_error = [](auto&& call, const std::string& needle) {
    try {
      call();
      ADD_FAILURE() << "no Error for: " << needle;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  PoseGraph2D graph;
  graph.add_node(Pose2::Identity());
  graph.add_node(pose2(1, 0, 0));
  const Eigen::Matrix3d info = Eigen::Matrix3d::Identity();
  expect_error([&] { graph.add_node(pose2(nan, 0, 0)); }, "not finite");
  expect_error([&] { graph.add_edge(0, 2, Pose2::Identity(), info, EdgeKind::kLoop); },
               "node 2 does not exist (the graph has 2 nodes)");
  expect_error([&] { graph.add_edge(1, 1, Pose2::Identity(), info, EdgeKind::kLoop); },
               "two different nodes");
  expect_error([&] { graph.add_edge(0, 1, pose2(0, 0, nan), info, EdgeKind::kOdometry); },
               "measurement is not finite");
  expect_error(
      [&] { graph.add_edge(0, 1, Pose2::Identity(), Eigen::Matrix3d::Zero(), EdgeKind::kLoop); },
      "not positive definite");
  Eigen::Matrix3d rank_deficient = Eigen::Matrix3d::Identity();
  rank_deficient(2, 2) = 0;
  expect_error([&] { graph.add_edge(0, 1, Pose2::Identity(), rank_deficient, EdgeKind::kLoop); },
               "not positive definite");
  Eigen::Matrix3d indefinite = Eigen::Matrix3d::Identity();
  indefinite(0, 0) = -1;
  expect_error([&] { graph.add_edge(0, 1, Pose2::Identity(), indefinite, EdgeKind::kLoop); },
               "not positive definite");
  Eigen::Matrix3d asymmetric = Eigen::Matrix3d::Identity();
  asymmetric(0, 1) = 0.5;
  expect_error([&] { graph.add_edge(0, 1, Pose2::Identity(), asymmetric, EdgeKind::kLoop); },
               "not symmetric");
  EXPECT_TRUE(graph.edges().empty());  // nothing was added by the failed calls

  PoseGraph3D graph3;
  graph3.add_node(Pose::Identity());
  Pose sheared = Pose::Identity();
  sheared.matrix()(0, 1) = 0.3;
  expect_error([&] { graph3.add_node(sheared); }, "not orthonormal");
  graph3.add_node(Pose::Identity());
  Matrix6d info3 = Matrix6d::Identity();
  info3(5, 5) = std::numeric_limits<double>::infinity();
  expect_error([&] { graph3.add_edge(0, 1, Pose::Identity(), info3, EdgeKind::kLoop); },
               "information matrix is not finite");
  expect_error(
      [&] { graph3.add_edge(5, 1, Pose::Identity(), Matrix6d::Identity(), EdgeKind::kLoop); },
      "edge 0 (5 -> 1): node 5 does not exist");
}

TEST(PoseGraph2D, ThousandNodesIncrementally) {
  // 25 laps of the square (1000 nodes); each node from the second lap on sees the node one lap
  // back every 5 steps. The graph is optimized as the sequence goes, after each lap's loops.
  const int count = 1000;
  std::vector<std::pair<int, int>> loops;
  for (int k = kNodesPerLap; k < count; k += 5) loops.push_back({k, k - kNodesPerLap});
  Square2D full(count, loops, PoseGraphConfig{});  // the truth, odometry and edges to replay

  PoseGraph2D graph;
  graph.add_node(full.odometry[0]);
  double last_ms = 0.0;
  int solves = 0;
  std::size_t edge = 0;
  for (int k = 1; k < count; ++k) {
    // New nodes are chained from the current (optimized) estimate of the previous one.
    const auto& odometry_edge = full.graph.edges()[edge++];
    graph.add_node(graph.pose(k - 1) * odometry_edge.measurement);
    graph.add_edge(k - 1, k, odometry_edge.measurement, odometry_edge.information,
                   EdgeKind::kOdometry);
    if (k % kNodesPerLap == kNodesPerLap - 1 && k > kNodesPerLap) {
      for (std::size_t e = count - 1; e < full.graph.edges().size(); ++e) {
        const auto& loop = full.graph.edges()[e];
        if (static_cast<int>(loop.from) <= k && static_cast<int>(loop.from) > k - kNodesPerLap)
          graph.add_edge(loop.from, loop.to, loop.measurement, loop.information, EdgeKind::kLoop);
      }
      const PoseGraphSummary summary = graph.optimize();
      EXPECT_TRUE(summary.outlier_edges.empty()) << "after node " << k;
      last_ms = summary.solve_ms;
      ++solves;
    }
  }
  // The whole graph once more, from the incremental answer, and once from the raw odometry.
  const PoseGraphSummary warm = graph.optimize();
  const PoseGraphSummary cold = full.graph.optimize();
  PoseGraphConfig build_only;
  build_only.max_iterations = 0;
  PoseGraph2D unsolved(build_only);
  for (const Pose2& T : full.odometry) unsolved.add_node(T);
  for (const auto& e : full.graph.edges())
    unsolved.add_edge(e.from, e.to, e.measurement, e.information, e.kind);
  const PoseGraphSummary build = unsolved.optimize();

  const double drift = max_position_error(full.odometry, full.truth);
  const double error = max_position_error(graph.poses(), full.truth);
  std::printf(
      "1000-node 2D graph (%zu edges): %d incremental solves, the last %.1f ms; whole "
      "graph %.1f ms (%d iterations) warm, %.1f ms (%d iterations) from odometry, %.1f ms "
      "to build and evaluate only; max position error %.2f m (odometry) -> %.3f m\n",
      graph.edges().size(), solves, last_ms, warm.solve_ms, warm.iterations, cold.solve_ms,
      cold.iterations, build.solve_ms, drift, error);
  EXPECT_EQ(graph.node_count(), 1000u);
  EXPECT_TRUE(cold.converged);
  EXPECT_LT(error, drift / 5);
  EXPECT_LT(max_position_error(full.graph.poses(), graph.poses()), 0.01);  // same optimum
}
