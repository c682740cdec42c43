#include <gtest/gtest.h>

#include <sstream>

#include "scanmatch/core/error.hpp"
#include "scanmatch/io/carmen.hpp"
#include "scanmatch/io/cloud_io.hpp"
#include "scanmatch/io/sequence.hpp"
#include "scanmatch/io/trajectory.hpp"
#include "test_helpers.hpp"

using namespace scanmatch;
using scanmatch::testing::error_of;
using scanmatch::testing::TempDir;
using scanmatch::testing::write_text;

namespace {
Trajectory sample_trajectory(bool with_times) {
  Trajectory t;
  for (int i = 0; i < 20; ++i) {
    t.poses.push_back(from_xyz_rpy(0.5 * i, 0.1 * i * i, -0.01 * i, 0.01 * i, -0.02 * i, 0.3 * i));
    if (with_times) t.timestamps.push_back(1600000000.0 + 0.1 * i);
  }
  return t;
}
}  // namespace

TEST(Trajectory, KittiAndTumRoundTrip) {
  TempDir dir;
  const Trajectory t = sample_trajectory(true);
  write_trajectory(dir.file("k.txt"), t, TrajectoryFormat::kKitti);
  write_trajectory(dir.file("t.txt"), t, TrajectoryFormat::kTum);
  const Trajectory k = read_trajectory(dir.file("k.txt"));
  const Trajectory u = read_trajectory(dir.file("t.txt"));
  ASSERT_EQ(k.size(), t.size());
  ASSERT_EQ(u.size(), t.size());
  EXPECT_FALSE(k.has_timestamps());
  ASSERT_TRUE(u.has_timestamps());
  for (std::size_t i = 0; i < t.size(); ++i) {
    EXPECT_TRUE(k.poses[i].isApprox(t.poses[i], 1e-12));
    EXPECT_TRUE(u.poses[i].isApprox(t.poses[i], 1e-12));
    EXPECT_NEAR(u.timestamps[i], t.timestamps[i], 1e-6);
  }
  EXPECT_NEAR(k.path_length(), t.path_length(), 1e-9);
}

TEST(Trajectory, HandWrittenFilesAndPathLength) {
  const Trajectory k = parse_trajectory(
      "# kitti\n1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 3 0 1 0 4 0 0 1 0\n", "k.txt", std::nullopt);
  ASSERT_EQ(k.size(), 2u);
  EXPECT_DOUBLE_EQ(k.path_length(), 5.0);
  const Trajectory t =
      parse_trajectory("0.0 0 0 0 0 0 0 1\n0.1 1 0 0 0 0 0.7071067811865476 0.7071067811865476\n",
                       "t.txt", std::nullopt);
  ASSERT_EQ(t.size(), 2u);
  EXPECT_NEAR(rotation_angle(t.poses[1]), M_PI / 2, 1e-12);
  EXPECT_DOUBLE_EQ(t.timestamps[1], 0.1);
}

TEST(Trajectory, BadInputGivesClearErrors) {
  const auto err = [](const std::string& text) {
    return error_of([&] { parse_trajectory(text, "bad.txt", std::nullopt); });
  };
  EXPECT_NE(err("").find("no poses"), std::string::npos);
  EXPECT_NE(err("1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1\n").find("line 2"),
            std::string::npos);
  EXPECT_NE(err("1 2 3 4 5\n").find("expected 12 numbers"), std::string::npos);
  EXPECT_NE(err("1 0 0 0 0 1 0 0 0 0 1 zero\n").find("not a number"), std::string::npos);
  EXPECT_NE(err("1 0 0 nan 0 1 0 0 0 0 1 0\n").find("non-finite"), std::string::npos);
  EXPECT_NE(err("2 0 0 0 0 1 0 0 0 0 1 0\n").find("not a rotation"), std::string::npos);
  EXPECT_NE(err("0 0 0 0 0 0 0 2\n").find("unit length"), std::string::npos);
  EXPECT_NE(
      error_of([] { read_trajectory("/nonexistent/poses.txt"); }).find("/nonexistent/poses.txt"),
      std::string::npos);
}

TEST(Trajectory, StreamingWriterFlushesEachLine) {
  TempDir dir;
  const Trajectory t = sample_trajectory(true);
  TrajectoryWriter writer(dir.file("s.txt"), TrajectoryFormat::kTum);
  writer.write(t.poses[0], t.timestamps[0]);
  writer.write(t.poses[1], t.timestamps[1]);
  // Readable before the writer is closed: an interrupted run keeps what it finished.
  EXPECT_EQ(read_trajectory(dir.file("s.txt")).size(), 2u);
  EXPECT_THROW(TrajectoryWriter(dir.file("no/such/folder.txt"), TrajectoryFormat::kKitti), Error);
}

TEST(Carmen, ParsesFlaserRobotLaserAndOdom) {
  const std::string text =
      "# CARMEN\nPARAM robot_use_laser on nohost 0\n"
      "FLASER 3 1.0 2.0 3.0 0.5 0.6 0.1 0.5 0.6 0.1 100.0 host 100.5\n"
      "ODOM 1 2 0.3 0.1 0.0 0 101.0 host 101.5\n"
      "ROBOTLASER1 0 -3.14159 6.28318 0.0174533 4.0 0.01 0 2 1.5 2.5 1 9 1 2 0.3 1 2 0.3 0 0 0 0 0 "
      "102.0 host 102.5\n";
  const CarmenLog log = parse_carmen_log(text, "t.log");
  ASSERT_EQ(log.scans.size(), 2u);
  ASSERT_EQ(log.odometry.size(), 1u);
  EXPECT_EQ(log.ignored_lines, 1u);
  const LaserScan2D& f = log.scans[0];
  EXPECT_EQ(f.ranges, (std::vector<float>{1, 2, 3}));
  EXPECT_NEAR(f.angle_min, -M_PI / 2, 1e-12);
  EXPECT_NEAR(f.angle_increment, M_PI / 2, 1e-12);  // 3 beams over 180 degrees
  EXPECT_TRUE(f.pose.isApprox(Eigen::Vector3d(0.5, 0.6, 0.1)));
  EXPECT_DOUBLE_EQ(f.timestamp, 100.5);
  const LaserScan2D& r = log.scans[1];
  EXPECT_NEAR(r.angle_min, -3.14159, 1e-12);
  EXPECT_NEAR(r.angle_increment, 0.0174533, 1e-12);
  EXPECT_EQ(r.remissions, (std::vector<float>{9}));
  EXPECT_DOUBLE_EQ(r.timestamp, 102.5);
  EXPECT_TRUE(log.odometry[0].pose.isApprox(Eigen::Vector3d(1, 2, 0.3)));
}

TEST(Carmen, EvenBeamCountSpreadsOverFieldOfView) {
  std::string line = "FLASER 180";
  for (int i = 0; i < 180; ++i) line += " 1";
  line += " 0 0 0 0 0 0 1 h 1\n";
  const CarmenLog log = parse_carmen_log(line, "t.log");
  EXPECT_NEAR(log.scans[0].angle_increment, M_PI / 180, 1e-12);
}

TEST(Carmen, RoundTripBothRecordKinds) {
  TempDir dir;
  CarmenLog log;
  for (int i = 0; i < 5; ++i) {
    LaserScan2D scan;
    scan.timestamp = 10.0 + i;
    scan.angle_min = -M_PI;
    scan.angle_increment = M_PI / 180;
    scan.max_range = 4.0f;
    for (int b = 0; b < 360; ++b) scan.ranges.push_back(0.5f + 0.01f * b);
    scan.pose = Eigen::Vector3d(i, 2 * i, 0.1 * i);
    log.scans.push_back(scan);
    log.odometry.push_back({10.0 + i + 0.5, Eigen::Vector3d(i, 0, 0), 0.1, 0.2, 0.0});
  }
  write_carmen_log(dir.file("r.log"), log, CarmenLaserRecord::kRobotLaser1);
  const CarmenLog back = read_carmen_log(dir.file("r.log"));
  ASSERT_EQ(back.scans.size(), 5u);
  ASSERT_EQ(back.odometry.size(), 5u);
  EXPECT_EQ(back.scans[3].ranges, log.scans[3].ranges);
  EXPECT_NEAR(back.scans[3].angle_min, -M_PI, 1e-12);
  EXPECT_NEAR(back.scans[3].angle_increment, M_PI / 180, 1e-12);
  EXPECT_TRUE(back.scans[4].pose.isApprox(log.scans[4].pose, 1e-9));
  write_carmen_log(dir.file("f.log"), log, CarmenLaserRecord::kFlaser);
  const CarmenLog flaser = read_carmen_log(dir.file("f.log"));
  ASSERT_EQ(flaser.scans.size(), 5u);
  EXPECT_EQ(flaser.scans[2].ranges, log.scans[2].ranges);
  EXPECT_NEAR(flaser.scans[2].timestamp, 12.0, 1e-6);
}

TEST(Carmen, BadInputGivesClearErrors) {
  const auto err = [](const std::string& text) {
    return error_of([&] { parse_carmen_log(text, "bad.log"); });
  };
  EXPECT_NE(err("FLASER 3 1 2 3 0 0 0 0 0 0 1 h\n").find("line 1"), std::string::npos);
  EXPECT_NE(err("FLASER -3 1 2 3\n").find("invalid beam count"), std::string::npos);
  EXPECT_NE(err("FLASER 999999999 1 2 3\n").find("invalid beam count"), std::string::npos);
  EXPECT_NE(err("FLASER 2 1 x 0 0 0 0 0 0 1 h 1\n").find("not a number"), std::string::npos);
  EXPECT_NE(err("ODOM 1 2 3\n").find("ODOM record has 4 fields"), std::string::npos);
  EXPECT_NE(err("PARAM a b\n").find("not a CARMEN log"), std::string::npos);
  EXPECT_NE(err("").find("not a CARMEN log"), std::string::npos);
}

TEST(Carmen, FlaserNoReturnReadingIsInferredFromTheLog) {
  // FLASER records carry no maximum range: a reading the far end of the log repeats is the
  // laser's "no return" (orebro logs 32.767 m), and readings from 2 cm below it are no returns.
  const auto flaser = [](const std::vector<double>& ranges) {
    std::ostringstream line;
    line << "FLASER " << ranges.size();
    for (double r : ranges) line << ' ' << r;
    line << " 0 0 0 0 0 0 1 host 1\n";
    return line.str();
  };
  std::string text, spread;
  for (int scan = 0; scan < 20; ++scan) {
    std::vector<double> ranges, plain;
    for (int beam = 0; beam < 181; ++beam) {
      const double range = 2.0 + 0.05 * beam + 0.01 * scan;
      ranges.push_back(beam % 9 == 0 ? 32.767 : (beam % 9 == 1 ? 32.759 : range));
      plain.push_back(range);
    }
    text += flaser(ranges);
    spread += flaser(plain);
  }
  // On by default; off, the scans keep 80 m.
  CarmenReadOptions as_points;
  as_points.infer_no_return = false;
  EXPECT_FLOAT_EQ(parse_carmen_log(text, "no_return.log", as_points).scans[0].max_range, 80.0f);
  const CarmenReadOptions inferring;
  const CarmenLog log = parse_carmen_log(text, "no_return.log");
  ASSERT_EQ(log.scans.size(), 20u);
  EXPECT_NEAR(log.scans[0].max_range, 32.747, 1e-4);
  EXPECT_NEAR(*no_return_reading(log.scans), 32.747, 1e-4);
  const Scan2D scan = scan_from_laser(log.scans[0]);
  EXPECT_EQ(scan.points.size(), 181u - 41u);  // 21 beams log 32.767, 20 log 32.759
  EXPECT_EQ(scan.misses.size(), 41u);
  // Far readings that spread (a far wall) are returns: the default stands.
  const CarmenLog plain = parse_carmen_log(spread, "plain.log", inferring);
  EXPECT_FLOAT_EQ(plain.scans[0].max_range, 80.0f);
  EXPECT_FALSE(no_return_reading(plain.scans));
  // Too few readings to tell.
  EXPECT_FALSE(no_return_reading({log.scans[0]}));
  // ROBOTLASER1 records carry their own.
  CarmenLog robot;
  robot.scans = log.scans;
  for (LaserScan2D& s : robot.scans) s.max_range = 40.0f;
  const TempDir dir;
  write_carmen_log(dir.file("robot.log"), robot, CarmenLaserRecord::kRobotLaser1);
  EXPECT_FLOAT_EQ(read_carmen_log(dir.file("robot.log"), inferring).scans[0].max_range, 40.0f);
}

TEST(Carmen, RealLogsHaveTheDocumentedScanCounts) {
  const std::string folder = scanmatch::testing::shared_data("data/2d/carmen");
  if (folder.empty()) GTEST_SKIP() << "../shared/data/2d/carmen not present";
  const std::pair<const char*, std::size_t> logs[] = {{"intel", 910}, {"aces", 440}, {"fhw", 488}};
  for (const auto& [name, scans] : logs) {
    const CarmenLog log = read_carmen_log(folder + "/" + name + "-corrected.log.gz");
    EXPECT_EQ(log.scans.size(), scans) << name;
    EXPECT_GE(log.scans.front().ranges.size(), 180u) << name;
    EXPECT_FALSE(log.odometry.empty()) << name;
  }
}

TEST(Sequence, FolderKittiAndDataSetLayouts) {
  TempDir dir;
  PointCloud cloud;
  cloud.points = {Point(1, 2, 3), Point(4, 5, 6)};
  cloud.intensity = {1, 2};
  std::filesystem::create_directories(dir.path() / "plain");
  for (int i = 2; i >= 0; --i)
    write_cloud(dir.file("plain/00000" + std::to_string(i) + ".pcd"), cloud);
  auto plain = open_sequence_folder(dir.file("plain"));
  EXPECT_EQ(plain->size(), 3u);
  Frame frame;
  std::vector<std::string> names;
  while (plain->next(frame)) names.push_back(std::filesystem::path(frame.name).filename().string());
  EXPECT_EQ(names, (std::vector<std::string>{"000000.pcd", "000001.pcd", "000002.pcd"}));
  EXPECT_FALSE(plain->ground_truth());

  std::filesystem::create_directories(dir.path() / "kitti/velodyne");
  for (int i = 0; i < 2; ++i)
    write_cloud(dir.file("kitti/velodyne/00000" + std::to_string(i) + ".bin"), cloud);
  write_text(dir.file("kitti/times.txt"), "0.0\n0.1\n");
  write_text(dir.file("kitti/poses.txt"), "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1 0 1 0 0 0 0 1 0\n");
  auto kitti = open_sequence_folder(dir.file("kitti"));
  ASSERT_TRUE(kitti->ground_truth());
  EXPECT_EQ(kitti->ground_truth()->size(), 2u);
  ASSERT_TRUE(kitti->next(frame));
  ASSERT_TRUE(kitti->next(frame));
  EXPECT_DOUBLE_EQ(frame.timestamp, 0.1);
  EXPECT_EQ(frame.cloud.size(), 2u);
  EXPECT_FALSE(kitti->next(frame));

  write_text(dir.file("kitti/times.txt"), "0.0\n");
  EXPECT_NE(error_of([&] { open_sequence_folder(dir.file("kitti")); }).find("1 times for 2 frames"),
            std::string::npos);
  std::filesystem::create_directories(dir.path() / "empty");
  EXPECT_NE(error_of([&] { open_sequence_folder(dir.file("empty")); }).find("no .pcd"),
            std::string::npos);
  EXPECT_THROW(open_sequence_folder(dir.file("missing")), Error);
}

TEST(Parsers, LinesOfOnlySeparatorsAreSkippedNotCrashes) {
  // Found by fuzzing: a line of separators tokenises to nothing.
  EXPECT_THROW(parse_carmen_log("; \n,,\n", "sep.log"), Error);
  EXPECT_EQ(parse_carmen_log(";\nODOM 1 2 3 0 0 0 1 h 1\n", "sep.log").odometry.size(), 1u);
  EXPECT_EQ(parse_trajectory(",,\n1 0 0 0 0 1 0 0 0 0 1 0\n", "sep.txt", std::nullopt).size(), 1u);
}
