// The run folder written by run_odometry: the ground truth beside the poses and the ATE in the
// summary, both from the source alone.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "scanmatch/eval/metrics.hpp"
#include "scanmatch/io/trajectory.hpp"
#include "scanmatch/odometry/run.hpp"
#include "scanmatch/sim/open_sequence.hpp"
#include "test_helpers.hpp"

using namespace scanmatch;
using scanmatch::testing::TempDir;

namespace {

nlohmann::json read_json(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

// Simulated frames without their ground truth.
class FramesOnly : public SequenceSource {
 public:
  explicit FramesOnly(std::unique_ptr<SequenceSource> inner) : inner_(std::move(inner)) {}
  std::size_t size() const override { return inner_->size(); }
  bool next(Frame& frame) override { return inner_->next(frame); }
  std::string describe() const override { return "frames only"; }

 private:
  std::unique_ptr<SequenceSource> inner_;
};

}  // namespace

TEST(OdometryRun, WritesTheGroundTruthOfTheFramesRunAndItsAte) {
  TempDir dir;
  SequenceOptions input;
  input.simulator.frames = 8;
  const auto source = open_sequence("sim:dynamic-outdoor-fast", input);
  RunOptions options;
  options.out_dir = dir.file("run");
  options.max_frames = 6;  // fewer than the source has: the ground truth follows the run
  options.quiet = true;
  const RunSummary summary = run_odometry(*source, OdometryConfig{}, options);
  ASSERT_EQ(summary.frames, 6u);
  ASSERT_TRUE(summary.ate.has_value());
  EXPECT_EQ(summary.ground_truth.size(), 6u);

  const Trajectory est = read_trajectory(dir.file("run/poses_tum.txt"));
  const Trajectory gt = read_trajectory(dir.file("run/poses_gt.txt"));
  const Trajectory gt_tum = read_trajectory(dir.file("run/poses_gt_tum.txt"));
  ASSERT_EQ(gt.size(), 6u);
  ASSERT_EQ(gt_tum.size(), 6u);
  EXPECT_EQ(gt_tum.timestamps, est.timestamps);
  // What `scanmatch eval` computes from the written files is what the run reports.
  const Association pairs = associate(gt_tum, est);
  const AteResult from_files = compute_ate(pairs.ground_truth, pairs.estimate);
  EXPECT_GT(from_files.path_length, 0.1);
  EXPECT_NEAR(summary.ate->rmse, from_files.rmse, 1e-9);
  EXPECT_NEAR(summary.ate->path_length, from_files.path_length, 1e-9);
  EXPECT_NEAR(compute_ate(gt.poses, est.poses).rmse, from_files.rmse, 1e-9);
  const auto json = read_json(dir.file("run/summary.json"));
  ASSERT_TRUE(json.contains("ate"));
  EXPECT_EQ(json["ate"]["poses"], 6);
  EXPECT_DOUBLE_EQ(json["ate"]["rmse_m"].get<double>(), summary.ate->rmse);
  EXPECT_DOUBLE_EQ(json["ate"]["rmse_percent_of_path"].get<double>(),
                   summary.ate->rmse_percent_of_path);
}

TEST(OdometryRun, WithoutGroundTruthThereIsNoneBesideThePoses) {
  TempDir dir;
  SequenceOptions input;
  input.simulator.frames = 3;
  FramesOnly source(open_sequence("sim:static-indoor", input));
  RunOptions options;
  options.out_dir = dir.file("run");
  options.quiet = true;
  const RunSummary summary = run_odometry(source, OdometryConfig{}, options);
  EXPECT_EQ(summary.frames, 3u);
  EXPECT_FALSE(summary.ate.has_value());
  EXPECT_TRUE(summary.ground_truth.empty());
  EXPECT_TRUE(std::filesystem::exists(dir.file("run/poses.txt")));
  EXPECT_FALSE(std::filesystem::exists(dir.file("run/poses_gt.txt")));
  EXPECT_FALSE(std::filesystem::exists(dir.file("run/poses_gt_tum.txt")));
  EXPECT_FALSE(read_json(dir.file("run/summary.json")).contains("ate"));
}
