// Runs the built CLI on temporary files: info on each format, convert round trips, error exits.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>

#include "scanmatch/io/carmen.hpp"
#include "scanmatch/io/cloud_io.hpp"
#include "scanmatch/io/trajectory.hpp"
#include "test_helpers.hpp"

using namespace scanmatch;
using scanmatch::testing::CliRun;
using scanmatch::testing::run_cli;
using scanmatch::testing::TempDir;
using scanmatch::testing::write_text;

namespace {
PointCloud small_cloud() {
  PointCloud c;
  for (int i = 0; i < 100; ++i) {
    c.points.emplace_back(0.1f * i, 1.0f, -0.5f * i);
    c.intensity.push_back(static_cast<float>(i));
  }
  return c;
}
}  // namespace

TEST(Cli, VersionAndHelp) {
  EXPECT_EQ(run_cli("--version").status, 0);
  const CliRun help = run_cli("--help");
  EXPECT_EQ(help.status, 0);
  EXPECT_NE(help.output.find("convert"), std::string::npos);
}

TEST(Cli, InfoOnEveryKind) {
  TempDir dir;
  const PointCloud cloud = small_cloud();
  for (const char* name : {"a.pcd", "a.ply", "a.bin", "a.xyz", "a.csv"}) {
    write_cloud(dir.file(name), cloud);
    const CliRun run = run_cli("info --json " + dir.file(name));
    EXPECT_EQ(run.status, 0) << run.output;
    EXPECT_NE(run.output.find("\"points\": 100"), std::string::npos) << name << run.output;
  }
  Trajectory t;
  for (int i = 0; i < 5; ++i) t.poses.push_back(from_xyz_rpy(i, 0, 0, 0, 0, 0));
  write_trajectory(dir.file("poses.txt"), t, TrajectoryFormat::kKitti);
  const CliRun traj = run_cli("info " + dir.file("poses.txt"));
  EXPECT_EQ(traj.status, 0);
  EXPECT_NE(traj.output.find("path_length_m: 4"), std::string::npos) << traj.output;
  EXPECT_NE(traj.output.find("poses: 5"), std::string::npos);

  CarmenLog log;
  log.scans.resize(3);
  for (auto& s : log.scans) s.ranges.assign(360, 1.0f);
  write_carmen_log(dir.file("scans.log"), log);
  const CliRun carmen = run_cli("info " + dir.file("scans.log"));
  EXPECT_EQ(carmen.status, 0);
  EXPECT_NE(carmen.output.find("laser_scans: 3"), std::string::npos) << carmen.output;
  EXPECT_NE(carmen.output.find("beams_max: 360"), std::string::npos);
}

TEST(Cli, ConvertRoundTripsCloudsAndTrajectories) {
  TempDir dir;
  const PointCloud cloud = small_cloud();
  write_cloud(dir.file("in.ply"), cloud);
  ASSERT_EQ(run_cli("convert " + dir.file("in.ply") + " " + dir.file("out.pcd") +
                    " --encoding binary_compressed")
                .status,
            0);
  const PointCloud back = read_cloud(dir.file("out.pcd"));
  EXPECT_EQ(back.points, cloud.points);
  EXPECT_EQ(back.intensity, cloud.intensity);

  Trajectory t;
  for (int i = 0; i < 4; ++i) t.poses.push_back(from_xyz_rpy(i, 2 * i, 0, 0.1 * i, 0, 0));
  write_trajectory(dir.file("k.txt"), t, TrajectoryFormat::kKitti);
  write_text(dir.file("times.txt"), "10\n10.1\n10.2\n10.3\n");
  ASSERT_EQ(run_cli("convert " + dir.file("k.txt") + " " + dir.file("t.txt") + " --times " +
                    dir.file("times.txt"))
                .status,
            0);
  const Trajectory tum = read_trajectory(dir.file("t.txt"));
  ASSERT_TRUE(tum.has_timestamps());
  EXPECT_DOUBLE_EQ(tum.timestamps[3], 10.3);
  EXPECT_TRUE(tum.poses[3].isApprox(t.poses[3], 1e-12));
}

TEST(Cli, ErrorsAreOneLineAndNonZero) {
  TempDir dir;
  write_text(dir.file("broken.pcd"),
             "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 5\nDATA binary\n");
  const CliRun run = run_cli("info " + dir.file("broken.pcd"));
  EXPECT_NE(run.status, 0);
  EXPECT_NE(run.output.find("broken.pcd"), std::string::npos);
  EXPECT_EQ(std::count(run.output.begin(), run.output.end(), '\n'), 1) << run.output;
  EXPECT_NE(run_cli("info " + dir.file("missing.ply")).status, 0);
  EXPECT_NE(run_cli("convert " + dir.file("missing.ply") + " " + dir.file("x.pcd")).status, 0);
  EXPECT_NE(run_cli("nosuchcommand").status, 0);
}
