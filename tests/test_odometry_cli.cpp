// `scanmatch odometry` end to end: the run folder, configuration files, Ctrl-C and bad input.
#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <thread>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "scanmatch/config/config_io.hpp"
#include "scanmatch/core/error.hpp"
#include "scanmatch/eval/metrics.hpp"
#include "scanmatch/io/trajectory.hpp"
#include "scanmatch/run/run_config.hpp"
#include "test_helpers.hpp"

using namespace scanmatch;
using scanmatch::testing::read_text;
using scanmatch::testing::run_cli;
using scanmatch::testing::TempDir;

namespace {
std::size_t count_lines(const std::string& path) {
  std::ifstream in(path);
  std::size_t n = 0;
  for (std::string line; std::getline(in, line);) n += !line.empty();
  return n;
}
}  // namespace

TEST(OdometryCli, WritesARunFolderWithOneLinePerFrame) {
  TempDir dir;
  const std::string out = dir.file("run");
  const auto r =
      run_cli("odometry sim:dynamic-outdoor-fast --frames 12 --out " + out + " --save-map --quiet");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(count_lines(out + "/poses.txt"), 12u);
  EXPECT_EQ(count_lines(out + "/poses_tum.txt"), 12u);
  EXPECT_EQ(count_lines(out + "/timing.csv"), 13u);  // header
  EXPECT_TRUE(std::filesystem::exists(out + "/map.pcd"));
  const std::string summary = read_text(out + "/summary.json");
  EXPECT_NE(summary.find("\"frames\": 12"), std::string::npos);
  EXPECT_NE(summary.find("\"interrupted\": false"), std::string::npos);
  EXPECT_NE(summary.find("\"fine\""), std::string::npos);
  // The estimate follows the simulator's ground truth written beside it.
  const Trajectory est = read_trajectory(out + "/poses.txt");
  const Trajectory gt = read_trajectory(out + "/poses_gt.txt");
  ASSERT_EQ(est.size(), gt.size());
  EXPECT_LT(compute_ate(gt.poses, est.poses).rmse, 0.1);
}

TEST(OdometryCli, ConfigurationRoundTripsAndRejectsUnknownKeys) {
  OdometryConfig c;
  c.method = "vgicp";
  c.voxel_size = 0.37;
  c.map_update = false;
  c.registration.solver.kernel.type = KernelType::kTukey;
  c.registration.loam.segments = 9;
  const std::string text = odometry_config_to_json(c);
  const OdometryConfig back = odometry_config_from_json(text, "test.json");
  EXPECT_EQ(odometry_config_to_json(back), text);
  EXPECT_EQ(back.method, "vgicp");
  EXPECT_EQ(back.registration.solver.kernel.type, KernelType::kTukey);
  try {
    odometry_config_from_json(R"({"voxel_size": 0.3, "voxle": 1})", "my.json");
    FAIL() << "unknown key accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("my.json"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("voxle"), std::string::npos);
  }
  EXPECT_THROW(odometry_config_from_json(R"({"deskew": 3})", "x.json"), Error);
  EXPECT_THROW(
      odometry_config_from_json(R"({"registration": {"solver": {"kernel": "bad"}}})", "x.json"),
      Error);
  EXPECT_THROW(odometry_config_from_json("{not json", "x.json"), Error);
  // The CLI reloads what a run wrote.
  TempDir dir;
  scanmatch::testing::write_text(dir.file("c.json"), R"({"method": "ndt", "voxel_size": 0.4})");
  const auto r = run_cli("odometry sim:static-indoor --frames 3 --quiet --out " + dir.file("run") +
                         " --config " + dir.file("c.json"));
  ASSERT_EQ(r.status, 0) << r.output;
  const OdometryConfig used = read_odometry_config(dir.file("run/config.json"));
  EXPECT_EQ(used.method, "ndt");
  EXPECT_DOUBLE_EQ(used.voxel_size, 0.4);
  // Options on the command line win over the file, each reaching its own setting.
  const auto r2 =
      run_cli("odometry sim:static-indoor --frames 3 --quiet --out " + dir.file("run2") +
              " --config " + dir.file("c.json") + " --voxel-resolution 0.7 --ndt-resolution 1.5");
  ASSERT_EQ(r2.status, 0) << r2.output;
  const OdometryConfig used2 = read_odometry_config(dir.file("run2/config.json"));
  EXPECT_DOUBLE_EQ(used2.registration.voxel_resolution, 0.7);
  EXPECT_DOUBLE_EQ(used2.ndt_resolution, 1.5);
  EXPECT_DOUBLE_EQ(used2.voxel_size, 0.4);
}

TEST(OdometryCli, BadInputFailsWithAClearMessage) {
  TempDir dir;
  auto r = run_cli("odometry " + dir.file("missing") + " --out " + dir.file("run"));
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("missing"), std::string::npos) << r.output;
  r = run_cli("odometry sim:static-indoor --method magic --out " + dir.file("run"));
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("magic"), std::string::npos) << r.output;
  // A folder whose third frame is truncated: the run stops with an error naming the file, and
  // keeps the frames it finished.
  const std::string seq = dir.file("seq");
  std::filesystem::create_directories(seq);
  ASSERT_EQ(run_cli("simulate static-indoor --frames 4 --quiet --out " + dir.file("sim")).status,
            0);
  for (int i = 0; i < 4; ++i) {
    const std::string name = "00000" + std::to_string(i) + ".pcd";
    std::filesystem::copy_file(dir.file("sim/frames/" + name), seq + "/" + name);
  }
  std::filesystem::resize_file(seq + "/000002.pcd", 400);
  r = run_cli("odometry " + seq + " --quiet --out " + dir.file("cut"));
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("000002.pcd"), std::string::npos) << r.output;
  EXPECT_EQ(count_lines(dir.file("cut/poses.txt")), 2u);
  // ... and its summary says so.
  std::ifstream summary_file(dir.file("cut/summary.json"));
  ASSERT_TRUE(summary_file.good());
  const auto summary = nlohmann::json::parse(summary_file);
  EXPECT_EQ(summary["frames"], 2);
  EXPECT_NE(summary["error"].get<std::string>().find("000002.pcd"), std::string::npos);
}

TEST(OdometryCli, CtrlCKeepsWhatWasDoneAndExits130) {
  TempDir dir;
  const std::string out = dir.file("run");
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    const int devnull = ::open("/dev/null", O_WRONLY);
    dup2(devnull, 1);
    dup2(devnull, 2);
    execl(SCANMATCH_CLI_PATH, SCANMATCH_CLI_PATH, "odometry", "sim:dynamic-outdoor", "--quiet",
          "--out", out.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  // Wait until some frames are done, then interrupt.
  for (int i = 0; i < 600 && count_lines(out + "/poses.txt") < 5; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  kill(pid, SIGINT);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 130);
  const std::size_t poses = count_lines(out + "/poses.txt");
  EXPECT_GE(poses, 5u);
  EXPECT_EQ(count_lines(out + "/timing.csv"), poses + 1);
  EXPECT_NE(read_text(out + "/summary.json").find("\"interrupted\": true"), std::string::npos);
}
