// Bags on the command line: `info` lists the topics; `odometry` on a bag of simulator frames gives
// the poses it gives on the same frames read from files; `map2d` reads LaserScan topics.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "bag_writer.hpp"
#include "scanmatch/io/bag/bag_sequence.hpp"
#include "scanmatch/io/bag/ros_messages.hpp"
#include "scanmatch/io/cloud_io.hpp"
#include "scanmatch/io/trajectory.hpp"
#include "scanmatch/sim/simulator.hpp"
#include "test_helpers.hpp"

namespace scanmatch {
namespace {
using scanmatch::testing::read_text;
using scanmatch::testing::run_cli;
using scanmatch::testing::TempDir;
using namespace scanmatch::test;

/// A PointCloud2 holding exactly the cloud's values (float x y z intensity time, u16 ring).
std::string cloud_message(const PointCloud& cloud, std::int64_t stamp_ns) {
  const std::vector<TestField> fields = {{"x", 7, 0},          {"y", 7, 4},     {"z", 7, 8},
                                         {"intensity", 7, 12}, {"ring", 4, 16}, {"time", 7, 20}};
  std::vector<std::vector<double>> values;
  for (std::size_t i = 0; i < cloud.size(); ++i)
    values.push_back({cloud.points[i].x(), cloud.points[i].y(), cloud.points[i].z(),
                      cloud.has_intensity() ? cloud.intensity[i] : 0.0f,
                      cloud.has_ring() ? static_cast<double>(cloud.ring[i]) : 0.0,
                      cloud.has_time() ? cloud.time[i] : 0.0f});
  return point_cloud2(false, stamp_ns, fields, 24, values);
}

TEST(BagCli, OdometryOnABagMatchesTheSameFramesFromFiles) {
  TempDir dir;
  sim::SimOptions options;
  options.preset = "dynamic-outdoor-fast";
  options.frames = 8;
  const sim::Simulator simulator(options);
  const std::string dataset = dir.file("dataset");
  sim::write_dataset(simulator, dataset, true);
  // The bag holds the frames as the files hold them (read back, so both runs see equal clouds).
  const auto files = open_sequence_folder(dataset);
  std::vector<TestMessage> messages;
  Frame frame;
  while (files->next(frame)) {
    const auto stamp = static_cast<std::int64_t>(std::llround(frame.timestamp * 1e9));
    messages.push_back({"/points", stamp + 1000, cloud_message(frame.cloud, stamp)});
    messages.push_back({"/imu", stamp + 2000, "x"});
  }
  const std::vector<TestTopic> topics = {{"/points", "sensor_msgs/PointCloud2"},
                                         {"/imu", "sensor_msgs/Imu"}};
  const std::string bag = dir.file("sim.bag");
  testing::write_text(bag, ros1_bag(topics, messages, "lz4", 4));

  const auto info = run_cli("info " + bag);
  ASSERT_EQ(info.status, 0) << info.output;
  EXPECT_NE(info.output.find("format: ROS 1 bag"), std::string::npos) << info.output;
  EXPECT_NE(info.output.find("/points  sensor_msgs/PointCloud2  ros1  8 messages"),
            std::string::npos)
      << info.output;

  const auto from_bag = run_cli("odometry " + bag + " --out " + dir.file("bag_run") + " --quiet");
  ASSERT_EQ(from_bag.status, 0) << from_bag.output;
  const auto from_files =
      run_cli("odometry " + dataset + " --out " + dir.file("files_run") + " --quiet");
  ASSERT_EQ(from_files.status, 0) << from_files.output;
  const Trajectory a = read_trajectory(dir.file("bag_run/poses.txt"));
  const Trajectory b = read_trajectory(dir.file("files_run/poses.txt"));
  ASSERT_EQ(a.size(), 8u);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i)
    EXPECT_TRUE(a.poses[i].matrix().isApprox(b.poses[i].matrix(), 1e-9)) << i;

  // A second cloud topic makes --topic necessary; the error lists the candidates.
  std::vector<TestTopic> two = topics;
  two.push_back({"/points2", "sensor_msgs/PointCloud2"});
  messages.push_back({"/points2", messages.back().time_ns, messages.front().data});
  const std::string bag2 = dir.file("two.bag");
  testing::write_text(bag2, ros1_bag(two, messages));
  const auto ambiguous = run_cli("odometry " + bag2 + " --out " + dir.file("x") + " --quiet");
  EXPECT_NE(ambiguous.status, 0);
  EXPECT_NE(ambiguous.output.find("choose one with --topic: /points, /points2"), std::string::npos)
      << ambiguous.output;
  const auto chosen =
      run_cli("odometry " + bag2 + " --topic /points2 --out " + dir.file("y") + " --quiet");
  EXPECT_EQ(chosen.status, 0) << chosen.output;
  const auto wrong = run_cli("odometry " + bag2 + " --topic /imu --out " + dir.file("z"));
  EXPECT_NE(wrong.status, 0);
  EXPECT_NE(wrong.output.find("sensor_msgs/Imu is not a point cloud type"), std::string::npos)
      << wrong.output;
}

// One container and message kind of a bag written from simulator frames.
struct BagKind {
  std::string file, container, compression, message;  // message: "cloud2" or "livox"
};

// The frame as the message carries it: a Livox CustomMsg holds times in integer ns, intensity as
// a byte and the ring as a line number.
std::string frame_message(const PointCloud& cloud, std::int64_t stamp, const BagKind& kind) {
  const bool cdr = kind.container != "ros1";
  if (kind.message == "cloud2" && !cdr) return cloud_message(cloud, stamp);
  if (kind.message == "cloud2") {
    const std::vector<TestField> fields = {{"x", 7, 0},          {"y", 7, 4},     {"z", 7, 8},
                                           {"intensity", 7, 12}, {"ring", 4, 16}, {"t", 6, 20}};
    std::vector<std::vector<double>> values;
    for (std::size_t i = 0; i < cloud.size(); ++i)
      values.push_back({cloud.points[i].x(), cloud.points[i].y(), cloud.points[i].z(),
                        cloud.has_intensity() ? cloud.intensity[i] : 0.0,
                        cloud.has_ring() ? static_cast<double>(cloud.ring[i]) : 0.0,
                        cloud.has_time() ? std::round(cloud.time[i] * 1e9) : 0.0});
    return point_cloud2(true, stamp, fields, 24, values);
  }
  std::vector<TestLivoxPoint> points;
  for (std::size_t i = 0; i < cloud.size(); ++i)
    points.push_back(
        {static_cast<std::uint32_t>(cloud.has_time() ? std::llround(cloud.time[i] * 1e9) : 0),
         cloud.points[i].x(), cloud.points[i].y(), cloud.points[i].z(),
         static_cast<std::uint8_t>(
             cloud.has_intensity() ? std::clamp(cloud.intensity[i], 0.0f, 255.0f) : 0.0f),
         0, static_cast<std::uint8_t>(cloud.has_ring() ? cloud.ring[i] : 0)});
  return livox_custom(cdr, stamp, points);
}

TEST(BagCli, EveryKindOfBagGivesThePosesOfTheSameFramesReadFromFiles) {
  // Each bag holds simulated frames; a copy of the data set holds the frames as the bag's
  // decoder delivers them (the message's own precision), so both runs must agree exactly.
  const std::vector<BagKind> kinds = {{"points.bag", "ros1", "bz2", "cloud2"},
                                      {"livox.bag", "ros1", "", "livox"},
                                      {"points.mcap", "mcap", "zstd", "cloud2"},
                                      {"livox.mcap", "mcap", "lz4", "livox"},
                                      {"points.db3", "db3", "", "cloud2"}};
  TempDir dir;
  sim::SimOptions options;
  options.preset = "dynamic-indoor";  // a MID-360: non-repetitive, as Livox recordings are
  constexpr std::size_t kFrames = 6;
  options.frames = kFrames;
  const sim::Simulator simulator(options);
  const std::string dataset = dir.file("dataset");
  sim::write_dataset(simulator, dataset, true);
  for (const BagKind& kind : kinds) {
    SCOPED_TRACE(kind.file);
    const std::string topic = kind.message == "livox" ? "/livox/lidar" : "/points";
    const std::string type = kind.message == "livox"
                                 ? "livox_ros_driver2/CustomMsg"
                                 : (kind.container == "ros1" ? "sensor_msgs/PointCloud2"
                                                             : "sensor_msgs/msg/PointCloud2");
    const std::vector<TestTopic> topics = {{topic, type}};
    std::vector<TestMessage> messages;
    std::string folder = "decoded_" + kind.file;  // a folder named *.bag would be a bag
    std::replace(folder.begin(), folder.end(), '.', '_');
    const std::string decoded = dir.file(folder);
    std::filesystem::copy(dataset, decoded, std::filesystem::copy_options::recursive);
    const auto files = open_sequence_folder(dataset);
    Frame frame;
    while (files->next(frame)) {
      const auto stamp = static_cast<std::int64_t>(std::llround(frame.timestamp * 1e9));
      messages.push_back({topic, stamp + 1000, frame_message(frame.cloud, stamp, kind)});
      BagMessage m;
      m.topic = topic;
      m.type = type;
      m.encoding = kind.container == "ros1" ? "ros1" : "cdr";
      m.data = messages.back().data;
      write_cloud(decoded + "/frames/" + std::filesystem::path(frame.name).filename().string(),
                  decode_cloud_message(m, kind.file));
    }
    const std::string bag = dir.file(kind.file);
    if (kind.container == "ros1")
      testing::write_text(bag, ros1_bag(topics, messages, kind.compression, 3));
    else if (kind.container == "mcap")
      testing::write_text(bag, mcap_file(topics, messages, kind.compression, 3));
    else
      write_db3(bag, topics, messages);

    const std::string from_bag = dir.file("run_" + folder), from_files = from_bag + "_files";
    const auto a = run_cli("odometry " + bag + " --out " + from_bag + " --quiet");
    ASSERT_EQ(a.status, 0) << a.output;
    const auto b = run_cli("odometry " + decoded + " --out " + from_files + " --quiet");
    ASSERT_EQ(b.status, 0) << b.output;
    const Trajectory bag_poses = read_trajectory(from_bag + "/poses.txt");
    const Trajectory file_poses = read_trajectory(from_files + "/poses.txt");
    ASSERT_EQ(bag_poses.size(), kFrames);
    ASSERT_EQ(bag_poses.size(), file_poses.size());
    for (std::size_t i = 0; i < bag_poses.size(); ++i)
      EXPECT_TRUE(bag_poses.poses[i].matrix().isApprox(file_poses.poses[i].matrix(), 1e-9)) << i;
    // And the bag's frames are the simulator's up to the message's precision: the run tracks.
    const Trajectory truth = read_trajectory(dataset + "/poses_gt.txt");
    EXPECT_LT(
        (bag_poses.poses.back().translation() - truth.poses[kFrames - 1].translation()).norm(),
        0.05);
  }
}

TEST(BagCli, TruncatedBagKeepsTheFramesBeforeTheFault) {
  TempDir dir;
  sim::SimOptions options;
  options.preset = "dynamic-outdoor-fast";
  options.frames = 6;
  const sim::Simulator simulator(options);
  std::vector<TestMessage> messages;
  for (std::size_t i = 0; i < simulator.size(); ++i) {
    const auto stamp = static_cast<std::int64_t>(i) * 100000000;
    messages.push_back({"/points", stamp, cloud_message(simulator.frame(i), stamp)});
  }
  const std::string full = mcap_file({{"/points", "sensor_msgs/msg/PointCloud2"}}, messages, "", 1,
                                     true);  // ros1 encoding, one message per chunk
  const std::string bag = dir.file("cut.mcap");
  testing::write_text(bag, full.substr(0, full.size() * 3 / 4));
  const auto r = run_cli("odometry " + bag + " --out " + dir.file("run") + " --quiet");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("cut.mcap"), std::string::npos) << r.output;
  const std::string summary = read_text(dir.file("run/summary.json"));
  EXPECT_NE(summary.find("\"error\""), std::string::npos) << summary;
  EXPECT_GE(read_trajectory(dir.file("run/poses.txt")).size(), 3u);
}

TEST(BagCli, Map2dReadsLaserScans) {
  TempDir dir;
  sim::SimOptions options;
  options.preset = "room-2d";
  options.frames = 5;
  const sim::Simulator simulator(options);
  std::vector<TestMessage> messages;
  for (std::size_t i = 0; i < simulator.size(); ++i) {
    const LaserScan2D s = simulator.scan_2d(i);
    const auto stamp = static_cast<std::int64_t>(std::llround(s.timestamp * 1e9));
    messages.push_back(
        {"/scan", stamp,
         laser_scan(true, stamp, static_cast<float>(s.angle_min),
                    static_cast<float>(s.angle_increment), s.max_range, s.ranges, {})});
  }
  const std::string bag = dir.file("scans.db3");
  write_db3(bag, {{"/scan", "sensor_msgs/msg/LaserScan"}}, messages);
  const std::vector<LaserScan2D> scans = read_bag_laser_scans(bag);
  ASSERT_EQ(scans.size(), 5u);
  EXPECT_EQ(scans[2].ranges.size(), simulator.scan_2d(2).ranges.size());
  const auto r = run_cli("map2d " + bag + " --out " + dir.file("run") + " --quiet");
  ASSERT_EQ(r.status, 0) << r.output;
  const Trajectory from_bag = read_trajectory(dir.file("run/poses_tum.txt"));
  EXPECT_EQ(from_bag.size(), 5u);

  // The same scans as a CARMEN log give the same poses.
  CarmenLog log;
  log.scans = scans;
  write_carmen_log(dir.file("scans.log"), log);
  const auto l =
      run_cli("map2d " + dir.file("scans.log") + " --out " + dir.file("log_run") + " --quiet");
  ASSERT_EQ(l.status, 0) << l.output;
  const Trajectory from_log = read_trajectory(dir.file("log_run/poses_tum.txt"));
  ASSERT_EQ(from_log.size(), from_bag.size());
  for (std::size_t i = 0; i < from_bag.size(); ++i)
    EXPECT_TRUE(from_bag.poses[i].matrix().isApprox(from_log.poses[i].matrix(), 1e-9)) << i;
}

}  // namespace
}  // namespace scanmatch
