// One run record for 2D and 3D (run/run_record.hpp): a run folder says what it is in
// summary.json, and timing.csv's columns, its reader and summary.json's keys come from one
// description each (core/record.hpp), so their keys cannot drift apart.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <set>

#include "scanmatch/io/record_csv.hpp"
#include "scanmatch/mapping/loop_counts.hpp"
#include "scanmatch/run/map2d_run.hpp"
#include "scanmatch/run/odometry_run.hpp"
#include "scanmatch/run/run_folder.hpp"
#include "scanmatch/sim/open_scans_2d.hpp"
#include "scanmatch/sim/open_sequence.hpp"
#include "test_helpers.hpp"

using namespace scanmatch;
using scanmatch::testing::read_text;
using scanmatch::testing::TempDir;
using scanmatch::testing::write_text;

namespace {

// The keys of a record's description, in its order.
template <typename Record>
std::vector<std::string> described_keys() {
  std::vector<std::string> keys;
  const Record defaults{};
  for_each_field(defaults, [&](const char* key, const auto&, const char*) { keys.push_back(key); });
  return keys;
}

std::vector<std::string> csv_columns(const std::string& path) {
  const std::string text = read_text(path);
  return record_csv_detail::split_cells(text.substr(0, text.find('\n')));
}

nlohmann::ordered_json read_ordered_json(const std::string& path) {
  return nlohmann::ordered_json::parse(read_text(path));
}

// A short map2d run and a short odometry run, both with loop closure, shared by the tests.
class RunRecord : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir;
    const Scans2D scans = load_scans_2d("sim:room-2d", {}, kScans);
    Map2DRunOptions map2d;
    map2d.quiet = true;
    map2d.loop_closure = true;
    map2d_ = new Map2DSummary(run_map2d(scans, dir_->file("map2d"), map2d));
    SequenceOptions input;
    input.simulator.frames = kFrames;
    const auto source = open_sequence("sim:dynamic-outdoor-fast", input);
    RunOptions odometry;
    odometry.out_dir = dir_->file("odometry");
    odometry.quiet = true;
    odometry.loop_closure = true;
    odometry_ = new RunSummary(run_odometry(*source, OdometryConfig{}, odometry));
  }
  static void TearDownTestSuite() {
    delete map2d_;
    delete odometry_;
    delete dir_;
  }
  static std::string map2d_file(const std::string& name) { return dir_->file("map2d/" + name); }
  static std::string odometry_file(const std::string& name) {
    return dir_->file("odometry/" + name);
  }

  static constexpr std::size_t kScans = 40, kFrames = 6;
  static inline TempDir* dir_ = nullptr;
  static inline Map2DSummary* map2d_ = nullptr;
  static inline RunSummary* odometry_ = nullptr;
};

}  // namespace

TEST_F(RunRecord, TimingCsvColumnsAreIndexTimestampThenTheDescribedKeys) {
  std::vector<std::string> scan = {"index", "timestamp"}, frame = scan;
  for (const std::string& key : described_keys<Scan2DStats>()) scan.push_back(key);
  for (const std::string& key : described_keys<FrameStats>()) frame.push_back(key);
  EXPECT_EQ(csv_columns(map2d_file("timing.csv")), scan);
  EXPECT_EQ(csv_columns(odometry_file("timing.csv")), frame);
  // One name each: the registration error is error_m, and weak_fit is written.
  EXPECT_EQ(std::set<std::string>(scan.begin(), scan.end()).count("error_m"), 1u);
  EXPECT_EQ(std::set<std::string>(scan.begin(), scan.end()).count("weak_fit"), 1u);
}

TEST_F(RunRecord, ARunFolderSaysWhatItIsAndIsReadBackByIt) {
  EXPECT_EQ(read_ordered_json(map2d_file("summary.json")).at("kind"), "map2d");
  EXPECT_EQ(read_ordered_json(odometry_file("summary.json")).at("kind"), "odometry");

  const RunFolder map2d = read_run_folder(dir_->file("map2d"));
  EXPECT_EQ(map2d.kind, "map2d");
  EXPECT_TRUE(map2d.timing.empty());
  ASSERT_EQ(map2d.scan_timing.size(), kScans);
  std::size_t bridged = 0;
  for (std::size_t i = 0; i < kScans; ++i) {
    EXPECT_EQ(map2d.scan_timing[i].index, i);
    EXPECT_NEAR(map2d.scan_timing[i].timestamp, map2d.poses.timestamps[i], 1e-6);
    bridged += map2d.scan_timing[i].stats.bridged;
  }
  EXPECT_EQ(bridged, map2d_->bridged);
  EXPECT_GT(map2d.scan_timing.back().stats.points, 100u);
  EXPECT_GT(map2d.scan_timing.back().stats.iterations, 0);

  const RunFolder odometry = read_run_folder(dir_->file("odometry"));
  EXPECT_EQ(odometry.kind, "odometry");
  EXPECT_TRUE(odometry.scan_timing.empty());
  ASSERT_EQ(odometry.timing.size(), kFrames);
  EXPECT_EQ(odometry.timing.back().stats.points_in, odometry_->stats.back().points_in);
}

TEST_F(RunRecord, FoldersWithoutAKindAreToldByTheirTimingCsv) {
  // Written before summary.json had "kind": map2d's timing.csv then began "scan,ms,".
  TempDir old;
  std::filesystem::create_directories(old.file("2d"));
  std::filesystem::create_directories(old.file("3d"));
  const std::string poses = read_text(map2d_file("poses_tum.txt"));
  write_text(old.file("2d/poses_tum.txt"), poses);
  write_text(old.file("2d/summary.json"), R"({"method": "sparse-icp", "scans_per_second": 50})");
  write_text(old.file("2d/timing.csv"),
             "scan,ms,iterations,points,pairs,error_m,bridged,open_step_from_prior,fit,weak_fit\n"
             "0,1.5,3,300,280,0.01,0,0,-1,0\n");
  const RunFolder map2d = read_run_folder(old.file("2d"));
  EXPECT_EQ(map2d.kind, "map2d");
  EXPECT_EQ(map2d.frames_per_second, 50.0);
  EXPECT_TRUE(map2d.timing.empty() && map2d.scan_timing.empty());

  write_text(old.file("3d/poses_tum.txt"), poses);
  write_text(old.file("3d/summary.json"), R"({"method": "ctf-icp"})");
  write_text(old.file("3d/timing.csv"), "index,timestamp,total_ms\n0,0.1,4.5\n");
  const RunFolder odometry = read_run_folder(old.file("3d"));
  EXPECT_EQ(odometry.kind, "odometry");
  ASSERT_EQ(odometry.timing.size(), 1u);
  EXPECT_EQ(odometry.timing[0].stats.total_ms, 4.5);

  write_text(old.file("3d/summary.json"), R"({"kind": "map3d"})");
  EXPECT_EQ(scanmatch::testing::error_of([&] { read_run_folder(old.file("3d")); }),
            old.file("3d/summary.json") + ": unknown kind of run 'map3d'");
}

TEST_F(RunRecord, SummaryLoopClosureHasTheDescribedCountsThenTheRunsOwn) {
  const auto keys_of = [](const nlohmann::ordered_json& j) {
    std::vector<std::string> keys;
    for (const auto& item : j.items()) keys.push_back(item.key());
    return keys;
  };
  const auto expected = [](std::vector<std::string> keys, const std::string& item) {
    for (const std::string& key :
         {std::string("accepted"), "ms_per_" + item, std::string("thread"), "wait_ms_per_" + item})
      keys.push_back(key);
    return keys;
  };
  const nlohmann::ordered_json map2d =
      read_ordered_json(map2d_file("summary.json")).at("loop_closure");
  const nlohmann::ordered_json odometry =
      read_ordered_json(odometry_file("summary.json")).at("loop_closure");
  EXPECT_EQ(keys_of(map2d), expected(described_keys<LoopClosure2DCounts>(), "scan"));
  EXPECT_EQ(keys_of(odometry), expected(described_keys<LoopClosure3DCounts>(), "frame"));
  // The values are the run's.
  ASSERT_TRUE(map2d_->loop_closure && odometry_->loop_closure);
  EXPECT_EQ(map2d.at("keyframes").get<std::size_t>(), map2d_->loop_closure->counts.keyframes);
  EXPECT_GT(map2d_->loop_closure->counts.keyframes, 1u);
  EXPECT_EQ(map2d.at("rejected_as_outliers").get<std::size_t>(),
            map2d_->loop_closure->counts.outliers);
  EXPECT_EQ(odometry.at("keyframes").get<std::size_t>(), odometry_->loop_closure->counts.keyframes);
  EXPECT_EQ(odometry.at("thread").get<bool>(), odometry_->loop_closure->thread);
}

TEST_F(RunRecord, SummaryOptionsAreTheConfiguration) {
  // Both runs' summary.json "options" come from the configuration's one description, as
  // config.json (odometry's config.json adds the run's keys: map export, loop closure).
  const nlohmann::ordered_json config = read_ordered_json(map2d_file("config.json"));
  const nlohmann::ordered_json summary = read_ordered_json(map2d_file("summary.json"));
  EXPECT_EQ(summary.at("options"), config);
  EXPECT_TRUE(config.at("loop_closure").get<bool>());
  EXPECT_EQ(summary.at("method"), config.at("mapper").at("registration").at("method"));
  EXPECT_GT(summary.at("rotation_period_s").get<double>(), 0.0);  // sim: room-2d's laser turns
  EXPECT_FALSE(summary.at("deskewed").get<bool>());               // deskew is off by default
  nlohmann::ordered_json odometry = read_ordered_json(odometry_file("config.json"));
  for (const char* run_key : {"loop_closure", "loop_closure_thread", "map_export", "loop"})
    EXPECT_EQ(odometry.erase(run_key), 1u) << run_key;
  EXPECT_EQ(read_ordered_json(odometry_file("summary.json")).at("options"), odometry);
}
