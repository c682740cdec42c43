// open_sequence: the one reader choice of every command (folders, bags, sim:PRESET) and the
// reference trajectory option.

#include <gtest/gtest.h>

#include <filesystem>

#include "scanmatch/core/error.hpp"
#include "scanmatch/io/cloud_io.hpp"
#include "scanmatch/io/file_util.hpp"
#include "scanmatch/sim/open_sequence.hpp"
#include "test_helpers.hpp"

namespace scanmatch {
namespace {

using testing::error_of;
using testing::TempDir;
using testing::write_text;

// Three frames of two points each in DIR/frames/, with times.txt beside them.
void write_frames(const TempDir& dir) {
  PointCloud cloud;
  cloud.points = {Point(1, 2, 3), Point(4, 5, 6)};
  std::filesystem::create_directories(dir.path() / "set/frames");
  for (int i = 0; i < 3; ++i)
    write_cloud(dir.file("set/frames/00000" + std::to_string(i) + ".pcd"), cloud);
  write_text(dir.file("set/times.txt"), "10.0\n10.3\n10.4\n");
}

TEST(OpenSequence, MissingInputsNameTheSpecAndWhatIsAccepted) {
  const std::string message = error_of([] { open_sequence("/no/such/folder"); });
  EXPECT_NE(message.find("/no/such/folder: no such sequence (a folder, a KITTI sequence, a bag "
                         "or sim:PRESET)"),
            std::string::npos)
      << message;
  EXPECT_NE(error_of([] { open_sequence("/no/such.bag"); }).find("no such sequence"),
            std::string::npos);
  EXPECT_NE(error_of([] { open_sequence("sim:nowhere"); }).find("nowhere"), std::string::npos);
}

TEST(OpenSequence, ChoosesTheReaderBySpec) {
  SequenceOptions options;
  options.simulator.frames = 2;
  options.simulator.seed = 3;
  const auto simulated = open_sequence("sim:static-indoor", options);
  EXPECT_EQ(simulated->size(), 2u);
  EXPECT_NE(simulated->describe().find("seed 3"), std::string::npos) << simulated->describe();

  TempDir dir;
  write_frames(dir);
  const auto folder = open_sequence(dir.file("set"));
  EXPECT_EQ(folder->size(), 3u);
  EXPECT_FALSE(folder->ground_truth());
  Frame frame;
  ASSERT_TRUE(folder->next(frame));
  ASSERT_TRUE(folder->next(frame));
  EXPECT_DOUBLE_EQ(frame.timestamp, 10.3);  // the data set's times.txt

  const std::string bag = testing::shared_data("data/bags/luminar_pointcloud2_lz4.bag");
  if (bag.empty()) GTEST_SKIP() << "../shared/data/bags not present";
  SequenceOptions topic;
  topic.topic = "/luminar_pointcloud";
  const auto frames = open_sequence(bag, topic);
  EXPECT_EQ(frames->size(), 5u);
  EXPECT_NE(frames->describe().find(".bag"), std::string::npos) << frames->describe();
}

TEST(OpenSequence, AReferenceFileIsTheGroundTruthAnchoredAtTheFirstFrame) {
  TempDir dir;
  write_frames(dir);
  // KITTI rows that do not start at the identity: x = 5, 6, 8.
  write_text(dir.file("odom.txt"),
             "1 0 0 5 0 1 0 0 0 0 1 0\n1 0 0 6 0 1 0 0 0 0 1 0\n1 0 0 8 0 1 0 0 0 0 1 0\n");
  SequenceOptions options;
  options.reference = dir.file("odom.txt");
  const auto source = open_sequence(dir.file("set"), options);
  ASSERT_TRUE(source->ground_truth());
  const Trajectory gt = *source->ground_truth();  // returned by value
  ASSERT_EQ(gt.size(), 3u);
  EXPECT_TRUE(gt.poses[0].isApprox(Pose::Identity(), 1e-12));
  EXPECT_NEAR(gt.poses[2].translation().x(), 3.0, 1e-12);
  EXPECT_NE(source->describe().find("reference " + dir.file("odom.txt")), std::string::npos);

  write_text(dir.file("short.txt"), "1 0 0 5 0 1 0 0 0 0 1 0\n");
  options.reference = dir.file("short.txt");
  const std::string message = error_of([&] { open_sequence(dir.file("set"), options); });
  EXPECT_NE(message.find(dir.file("short.txt")), std::string::npos) << message;
  EXPECT_NE(message.find("1 poses for the 3 frames"), std::string::npos) << message;
  options.reference = dir.file("missing.txt");
  EXPECT_NE(error_of([&] { open_sequence(dir.file("set"), options); }).find("missing.txt"),
            std::string::npos);
}

TEST(OpenSequence, OdometryTakesAReferenceForItsAte) {
  TempDir dir;
  const auto run = testing::run_cli("odometry sim:static-indoor --frames 3 --quiet --out " +
                                    dir.file("run") + " --reference " + dir.file("none.txt"));
  EXPECT_NE(run.status, 0);
  EXPECT_NE(run.output.find(dir.file("none.txt")), std::string::npos) << run.output;
  write_text(dir.file("still.txt"),
             "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1 0\n"
             "1 0 0 0 0 1 0 0 0 0 1 0\n");
  const auto with_reference =
      testing::run_cli("odometry sim:static-indoor --frames 3 --quiet --out " + dir.file("ok") +
                       " --reference " + dir.file("still.txt"));
  ASSERT_EQ(with_reference.status, 0) << with_reference.output;
  const std::string summary = read_file_bytes(dir.file("ok/summary.json"));
  EXPECT_NE(summary.find("\"ate\""), std::string::npos);
  EXPECT_NE(summary.find("reference " + dir.file("still.txt")), std::string::npos);
  const auto missing =
      testing::run_cli("odometry " + dir.file("nothing") + " --out " + dir.file("run2"));
  EXPECT_NE(missing.status, 0);
  EXPECT_NE(missing.output.find("no such sequence"), std::string::npos) << missing.output;
}

}  // namespace
}  // namespace scanmatch
