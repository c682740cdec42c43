#include <gtest/gtest.h>

#include <cmath>

#include "scanmatch/core/error.hpp"
#include "scanmatch/eval/metrics.hpp"
#include "test_helpers.hpp"

using namespace scanmatch;

namespace {
// A straight drive along x with `steps` poses `step` metres apart.
std::vector<Pose> straight_line(std::size_t steps, double step) {
  std::vector<Pose> poses;
  for (std::size_t i = 0; i < steps; ++i)
    poses.push_back(from_xyz_rpy(step * static_cast<double>(i), 0, 0, 0, 0, 0));
  return poses;
}
}  // namespace

TEST(Ate, IdenticalTrajectoriesGiveZero) {
  const auto gt = straight_line(50, 1.0);
  const AteResult r = compute_ate(gt, gt);
  EXPECT_EQ(r.poses, 50u);
  EXPECT_DOUBLE_EQ(r.rmse, 0.0);
  EXPECT_DOUBLE_EQ(r.max, 0.0);
  EXPECT_DOUBLE_EQ(r.path_length, 49.0);
}

TEST(Ate, ConstantOffsetWithAndWithoutAlignment) {
  const auto gt = straight_line(20, 0.5);
  std::vector<Pose> est;
  for (const Pose& p : gt) est.push_back(from_xyz_rpy(0, 0.3, 0.4, 0, 0, 0) * p);
  const AteResult none = compute_ate(gt, est, Alignment::kNone);
  EXPECT_NEAR(none.rmse, 0.5, 1e-12);
  EXPECT_NEAR(none.median, 0.5, 1e-12);
  EXPECT_NEAR(none.rmse_percent_of_path, 100.0 * 0.5 / 9.5, 1e-9);
  EXPECT_NEAR(compute_ate(gt, est, Alignment::kSe3).rmse, 0.0, 1e-9);
}

TEST(Ate, LinearDriftHasKnownRmse) {
  // Error grows linearly 0, 0.01, ..., 0.09 m: rmse = 0.01 * sqrt(mean(i^2)), mean(i^2) = 28.5.
  const auto gt = straight_line(10, 1.0);
  std::vector<Pose> est;
  for (std::size_t i = 0; i < gt.size(); ++i)
    est.push_back(from_xyz_rpy(0, 0.01 * static_cast<double>(i), 0, 0, 0, 0) * gt[i]);
  const AteResult r = compute_ate(gt, est);
  EXPECT_NEAR(r.rmse, 0.01 * std::sqrt(28.5), 1e-12);
  EXPECT_NEAR(r.mean, 0.045, 1e-12);
  EXPECT_NEAR(r.median, 0.045, 1e-12);
  EXPECT_NEAR(r.max, 0.09, 1e-12);
  EXPECT_NEAR(r.final_drift, 0.09, 1e-12);
}

TEST(Ate, StillSensorReportsDriftNotPercent) {
  const std::vector<Pose> gt(30, Pose::Identity());
  std::vector<Pose> est(30, Pose::Identity());
  est.back() = from_xyz_rpy(0.02, 0, 0, 0, 0, 0);
  const AteResult r = compute_ate(gt, est);
  EXPECT_DOUBLE_EQ(r.path_length, 0.0);
  EXPECT_DOUBLE_EQ(r.rmse_percent_of_path, 0.0);
  EXPECT_NEAR(r.final_drift, 0.02, 1e-12);
  EXPECT_NEAR(r.max, 0.02, 1e-12);
}

TEST(Umeyama, RecoversKnownSimilarity) {
  const Pose T = from_xyz_rpy(1, -2, 3, 0.3, -0.2, 1.1);
  const double scale = 1.7;
  std::vector<Eigen::Vector3d> from, to;
  for (int i = 0; i < 20; ++i) {
    const Eigen::Vector3d p(std::sin(i), std::cos(3 * i), 0.1 * i);
    from.push_back(p);
    to.push_back(scale * (T.linear() * p) + T.translation());
  }
  const Similarity s = umeyama_alignment(from, to, true);
  EXPECT_NEAR(s.scale, scale, 1e-9);
  EXPECT_TRUE(s.transform.isApprox(T, 1e-9));
  const Similarity rigid = umeyama_alignment(from, to, false);
  EXPECT_DOUBLE_EQ(rigid.scale, 1.0);
}

TEST(Rpe, KnownPerStepRotationError) {
  // The estimate turns 0.001 rad further each step than the ground truth.
  const auto gt = straight_line(40, 1.0);
  std::vector<Pose> est;
  for (std::size_t i = 0; i < gt.size(); ++i)
    est.push_back(gt[i] * from_xyz_rpy(0, 0, 0, 0, 0, 0.001 * static_cast<double>(i)));
  const RpeResult r = compute_rpe_frames(gt, est, 1);
  EXPECT_EQ(r.pairs, 39u);
  EXPECT_NEAR(r.rotation_mean, 0.001 * 180.0 / M_PI, 1e-9);
  EXPECT_NEAR(r.rotation_rmse, 0.001 * 180.0 / M_PI, 1e-9);
  const RpeResult by_distance = compute_rpe_distance(gt, est, 5.0);
  EXPECT_EQ(by_distance.pairs, 35u);
  EXPECT_NEAR(by_distance.rotation_mean, 0.005 * 180.0 / M_PI, 1e-9);
}

TEST(Rpe, RelativeErrorsLocateTheBadStep) {
  // One step of the estimate is 0.3 m too long and turned 2 degrees; the others are exact.
  const auto gt = straight_line(10, 1.0);
  std::vector<Pose> est = {gt[0]};
  for (std::size_t i = 1; i < gt.size(); ++i) {
    Pose step = gt[i - 1].inverse() * gt[i];
    if (i == 6) step = step * from_xyz_rpy(0.3, 0, 0, 0, 0, 2.0 * M_PI / 180.0);
    est.push_back(est.back() * step);
  }
  const RelativeErrors e = relative_errors(gt, est, 1);
  ASSERT_EQ(e.translation.size(), 9u);
  ASSERT_EQ(e.rotation.size(), 9u);
  for (std::size_t k = 0; k < e.translation.size(); ++k) {
    // Entry k is the step from pose k to pose k + 1: the bad one is entry 5.
    EXPECT_NEAR(e.translation[k], k == 5 ? 0.3 : 0.0, 1e-9) << k;
    EXPECT_NEAR(e.rotation[k], k == 5 ? 2.0 : 0.0, 1e-9) << k;
  }
  // compute_rpe_frames summarises the same errors.
  EXPECT_NEAR(compute_rpe_frames(gt, est, 1).translation_rmse, std::sqrt(0.09 / 9.0), 1e-9);
  EXPECT_THROW(relative_errors(gt, est, 0), Error);
}

TEST(KittiDrift, OnePercentScaleDriftOnStraightLine) {
  // The estimate travels 1 % too far. The devkit normalises by the nominal length while its last
  // frame lies one step beyond it, so the figure is 1 % * (L + step) / L, averaged.
  const double step = 0.5;
  const auto gt = straight_line(1800, step);  // 899.5 m
  std::vector<Pose> est;
  for (const Pose& p : gt) est.push_back(from_xyz_rpy(1.01 * p.translation().x(), 0, 0, 0, 0, 0));
  const KittiDriftResult r = compute_kitti_drift(gt, est);
  ASSERT_EQ(r.lengths_used.size(), 8u);
  EXPECT_GT(r.translation_percent, 1.0);
  EXPECT_LT(r.translation_percent, 1.0 * (100.0 + step) / 100.0 + 1e-9);
  EXPECT_NEAR(r.rotation_deg_per_100m, 0.0, 1e-9);
  // 100 m segments start every 10th frame while the path has 100 m left: 1800 - 201 frames.
  EXPECT_GT(r.segments, 0u);
}

TEST(KittiDrift, ShortPathUsesOnlyTheLengthsItAllows) {
  const auto gt = straight_line(500, 0.5);  // 249.5 m: only 100 and 200 m segments fit
  const KittiDriftResult r = compute_kitti_drift(gt, gt);
  ASSERT_EQ(r.lengths_used.size(), 2u);
  EXPECT_DOUBLE_EQ(r.translation_percent, 0.0);
}

TEST(Associate, ByIndexRefusesMismatchUnlessPartial) {
  Trajectory gt, est;
  gt.poses = straight_line(10, 1.0);
  est.poses = straight_line(8, 1.0);
  EXPECT_THROW(associate(gt, est), Error);
  const Association a = associate(gt, est, true);
  EXPECT_EQ(a.estimate.size(), 8u);
  EXPECT_EQ(a.estimate_index.size(), 8u);
  EXPECT_EQ(a.estimate_index.back(), 7u);
  EXPECT_FALSE(a.by_timestamp);
}

TEST(Associate, ByTimestampMatchesNearest) {
  Trajectory gt, est;
  gt.poses = straight_line(10, 1.0);
  for (int i = 0; i < 10; ++i) gt.timestamps.push_back(100.0 + 0.1 * i);
  est.poses = {gt.poses[2], gt.poses[5]};
  est.timestamps = {100.2005, 100.4999};
  const Association a = associate(gt, est, true);
  ASSERT_EQ(a.estimate.size(), 2u);
  EXPECT_TRUE(a.by_timestamp);
  EXPECT_TRUE(a.ground_truth[0].isApprox(gt.poses[2]));
  EXPECT_TRUE(a.ground_truth[1].isApprox(gt.poses[5]));
  EXPECT_EQ(a.estimate_index, (std::vector<std::size_t>{0, 1}));
  EXPECT_THROW(associate(gt, est, false), Error);  // 2 of 10 matched
}

TEST(Cli, EvalOfGroundTruthAgainstItselfIsZero) {
  scanmatch::testing::TempDir dir;
  const auto sim = scanmatch::testing::run_cli(
      "simulate dynamic-outdoor-fast --frames 30 --quiet --out " + dir.file("ds"));
  ASSERT_EQ(sim.status, 0) << sim.output;
  const auto run = scanmatch::testing::run_cli("eval --json --gt " + dir.file("ds/poses_gt.txt") +
                                               " --est " + dir.file("ds/poses_gt_tum.txt"));
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_NE(run.output.find("\"rmse_m\": 0.0"), std::string::npos) << run.output;
  // KITTI poses have no timestamps: association by index, and it says so.
  EXPECT_NE(run.output.find("by index"), std::string::npos);
  const auto mismatch = scanmatch::testing::run_cli("eval --gt " + dir.file("ds/poses_gt.txt") +
                                                    " --est " + dir.file("ds/times.txt"));
  EXPECT_NE(mismatch.status, 0);
}
