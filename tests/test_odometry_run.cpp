// The run folder written by run_odometry: the ground truth beside the poses and the ATE in the
// summary, both from the source alone; every described frame statistic in timing.csv and
// summary.json.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "scanmatch/eval/metrics.hpp"
#include "scanmatch/io/trajectory.hpp"
#include "scanmatch/run/odometry_run.hpp"
#include "scanmatch/sim/open_sequence.hpp"
#include "test_helpers.hpp"

using namespace scanmatch;
using scanmatch::testing::read_text;
using scanmatch::testing::TempDir;

namespace {

nlohmann::json read_json(const std::string& path) {
  return nlohmann::json::parse(read_text(path));
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

// Runs the defaults on `max_frames` (0: all) of `frames` simulated frames of `preset` into `out`.
RunSummary run_simulated(const std::string& preset, int frames, std::size_t max_frames,
                         const std::string& out) {
  SequenceOptions input;
  input.simulator.frames = static_cast<std::size_t>(frames);
  const auto source = open_sequence("sim:" + preset, input);
  RunOptions options;
  options.out_dir = out;
  options.max_frames = max_frames;
  options.quiet = true;
  return run_odometry(*source, OdometryConfig{}, options);
}

}  // namespace

TEST(OdometryRun, WritesTheGroundTruthOfTheFramesRunAndItsAte) {
  TempDir dir;
  // Fewer frames run than the source has: the ground truth follows the run.
  const RunSummary summary = run_simulated("dynamic-outdoor-fast", 8, 6, dir.file("run"));
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

// Every field and stage of the description (frame_stats.hpp) reaches timing.csv and summary.json.
TEST(OdometryRun, TimingAndSummaryHoldEveryDescribedFieldAndStage) {
  TempDir dir;
  const RunSummary summary = run_simulated("static-indoor", 3, 0, dir.file("run"));
  ASSERT_EQ(summary.frames, 3u);
  EXPECT_EQ(read_text(dir.file("run/timing.csv")).substr(0, timing_csv_header().size() + 1),
            timing_csv_header() + "\n");
  const std::vector<FrameRecord> rows = read_timing_csv(dir.file("run/timing.csv"));
  ASSERT_EQ(rows.size(), 3u);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(rows[i].index, i);
    EXPECT_EQ(timing_csv_row(i, rows[i].timestamp, rows[i].stats),
              timing_csv_row(i, rows[i].timestamp, summary.stats[i]));
  }

  const auto json = nlohmann::ordered_json::parse(read_text(dir.file("run/summary.json")));
  std::vector<std::string> stages;
  for (const auto& [name, value] : json["stages"].items()) {
    stages.push_back(name);
    EXPECT_EQ(value["max_ms"].get<double>(), summary.stage(name).max_ms);
  }
  std::vector<std::string> described;
  for (const StageStatistics& s : stage_statistics({})) described.push_back(s.name);
  EXPECT_EQ(stages, described);
  EXPECT_THROW(summary.stage("no-such-stage"), std::out_of_range);
}
