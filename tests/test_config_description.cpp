// The one configuration description: JSON keys, flags and the --config override derive from it.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <set>

#include "scanmatch/config/config_io.hpp"
#include "scanmatch/core/error.hpp"
#include "scanmatch/io/file_util.hpp"
#include "scanmatch/run/run_config.hpp"
#include "scanmatch/run/run_config_fields.hpp"
#include "test_helpers.hpp"

namespace scanmatch {
namespace {

struct FlagCollector {
  std::vector<std::string> flags;
  template <typename T>
  void operator()(const char*, T&, const char* flag, const char*) {
    if (flag) flags.emplace_back(flag);
  }
  template <typename S>
  void nested(const char*, S& options) {
    describe(options, *this);
  }
};

template <typename Config>
std::vector<std::string> flags_of() {
  Config config;
  FlagCollector collector;
  describe(config, collector);
  return collector.flags;
}

TEST(ConfigDescription, FlagsAreUniqueAndSpelledLikeOptions) {
  for (const auto& flag : flags_of<Map2DRunOptions>()) EXPECT_EQ(flag.rfind("--", 0), 0u) << flag;
  const auto map2d = flags_of<Map2DRunOptions>();
  EXPECT_EQ(std::set<std::string>(map2d.begin(), map2d.end()).size(), map2d.size());
  FlagCollector collector;
  collector.flags = flags_of<OdometryConfig>();
  std::set<std::string> seen;
  for (const auto& flag : collector.flags) {
    EXPECT_TRUE(seen.insert(flag).second) << flag << " is described twice";
    EXPECT_EQ(flag.rfind("--", 0), 0u) << flag;
  }
  EXPECT_TRUE(seen.count("--max-iterations"));
  EXPECT_TRUE(seen.count("--voxel-resolution"));
}

// Every option of `odometry` and `register` that shapes a result is described, so config.json
// (odometry) and the Python keywords see it.
TEST(ConfigDescription, RunAndRegisterOptionsAreDescribedOnce) {
  const auto run = flags_of<OdometryRunConfig>();
  const std::set<std::string> run_flags(run.begin(), run.end());
  EXPECT_EQ(run_flags.size(), run.size());
  for (const char* flag :
       {"--no-fine", "--no-map-update", "--no-deskew", "--save-map", "--map-format",
        "--map-export-voxel", "--map-export-radius", "--loop-closure", "--no-loop-closure-thread"})
    EXPECT_TRUE(run_flags.count(flag)) << flag;
  const auto pair = flags_of<PairRegistrationOptions>();
  const std::set<std::string> pair_flags(pair.begin(), pair.end());
  EXPECT_EQ(pair_flags.size(), pair.size());
  EXPECT_TRUE(pair_flags.count("--voxel"));
  EXPECT_TRUE(pair_flags.count("--max-iterations"));
}

TEST(ConfigDescription, RunOptionsAndAblationsRoundTripThroughConfigJson) {
  testing::TempDir dir;
  OdometryRunConfig changed;
  changed.odometry.fine_stage = false;
  changed.odometry.map_update = false;
  changed.odometry.deskew = false;
  changed.output.write_map = true;
  changed.output.map_format = "ply";
  changed.output.map_voxel_size = 0.35;
  changed.output.map_export_radius = 42.0;
  changed.output.loop_closure = true;
  changed.output.loop_closure_thread = false;
  changed.output.out_dir = "not/configuration";  // per invocation: not written
  const std::string text = odometry_run_config_to_json(changed);
  EXPECT_EQ(text.find("not/configuration"), std::string::npos) << text;
  testing::write_text(dir.file("config.json"), text);

  const OdometryRunConfig back = read_odometry_run_config(dir.file("config.json"));
  EXPECT_FALSE(back.odometry.fine_stage);
  EXPECT_FALSE(back.odometry.map_update);
  EXPECT_FALSE(back.odometry.deskew);
  EXPECT_TRUE(back.output.write_map);
  EXPECT_EQ(back.output.map_format, "ply");
  EXPECT_DOUBLE_EQ(back.output.map_voxel_size, 0.35);
  EXPECT_DOUBLE_EQ(back.output.map_export_radius, 42.0);
  EXPECT_TRUE(back.output.loop_closure);
  EXPECT_FALSE(back.output.loop_closure_thread);
  EXPECT_TRUE(back.output.out_dir.empty());
  EXPECT_EQ(odometry_run_config_to_json(back), text);
  // The pipeline's part alone reads the same file.
  EXPECT_FALSE(read_odometry_config(dir.file("config.json")).fine_stage);

  // A config.json written before "map_export" existed keeps the base's map options.
  testing::write_text(dir.file("old.json"), R"({"method": "ndt", "fine_stage": false})");
  const OdometryRunConfig old = read_odometry_run_config(dir.file("old.json"), changed);
  EXPECT_EQ(old.odometry.method, "ndt");
  EXPECT_EQ(old.output.map_format, "ply");
  EXPECT_DOUBLE_EQ(old.output.map_voxel_size, 0.35);
  const OdometryRunConfig plain = read_odometry_run_config(dir.file("old.json"));
  EXPECT_FALSE(plain.output.write_map);
  EXPECT_EQ(plain.output.map_format, "pcd");

  testing::write_text(dir.file("bad.json"), R"({"map_export": {"fromat": "ply"}})");
  try {
    read_odometry_run_config(dir.file("bad.json"));
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("map_export.fromat"), std::string::npos) << e.what();
  }
}

// A run's config.json repeats its ablation and map export switches when given to --config; a
// switch given beside --config still wins.
TEST(ConfigDescription, OdometryRunsRepeatTheirSwitchesFromConfigJson) {
  testing::TempDir dir;
  const std::string common = "odometry sim:static-indoor --frames 3 --threads 1 --quiet ";
  const auto first =
      testing::run_cli(common + "--no-fine --save-map --map-format ply --out " + dir.file("first"));
  ASSERT_EQ(first.status, 0) << first.output;
  EXPECT_TRUE(std::filesystem::exists(dir.file("first/map.ply")));
  const OdometryRunConfig written = read_odometry_run_config(dir.file("first/config.json"));
  EXPECT_FALSE(written.odometry.fine_stage);
  EXPECT_TRUE(written.odometry.map_update);
  EXPECT_TRUE(written.output.write_map);
  EXPECT_EQ(written.output.map_format, "ply");

  const auto again = testing::run_cli(common + "--config " + dir.file("first/config.json") +
                                      " --out " + dir.file("again"));
  ASSERT_EQ(again.status, 0) << again.output;
  EXPECT_EQ(read_file_bytes(dir.file("again/config.json")),
            read_file_bytes(dir.file("first/config.json")));
  EXPECT_TRUE(std::filesystem::exists(dir.file("again/map.ply")));
  EXPECT_EQ(read_file_bytes(dir.file("again/poses.txt")),
            read_file_bytes(dir.file("first/poses.txt")));

  const auto more = testing::run_cli(common + "--config " + dir.file("first/config.json") +
                                     " --no-deskew --map-format pcd --out " + dir.file("more"));
  ASSERT_EQ(more.status, 0) << more.output;
  const OdometryRunConfig overridden = read_odometry_run_config(dir.file("more/config.json"));
  EXPECT_FALSE(overridden.odometry.fine_stage);  // from the file
  EXPECT_FALSE(overridden.odometry.deskew);      // given
  EXPECT_EQ(overridden.output.map_format, "pcd");
  EXPECT_TRUE(std::filesystem::exists(dir.file("more/map.pcd")));
}

TEST(ConfigDescription, EveryFieldRoundTripsThroughJson) {
  OdometryConfig changed;
  changed.method = "gicp";
  changed.voxel_size = 0.37;
  changed.merge_threshold = 9;
  changed.deskew = false;
  changed.registration.voxel_resolution = 2.5;
  changed.registration.solver.kernel.type = KernelType::kTukey;
  changed.registration.solver.max_iterations = 11;
  changed.registration.loam.rings = 16;
  const std::string text = odometry_config_to_json(changed);
  const OdometryConfig back = odometry_config_from_json(text, "test");
  EXPECT_EQ(odometry_config_to_json(back), text);
  EXPECT_EQ(back.registration.solver.kernel.type, KernelType::kTukey);
  EXPECT_EQ(back.registration.loam.rings, 16);
  EXPECT_NE(text, odometry_config_to_json(OdometryConfig{}));
}

TEST(ConfigDescription, OnlyTheGivenFlagsOverrideTheFile) {
  OdometryConfig file;
  file.voxel_size = 0.4;
  file.map_radius = 30.0;
  file.registration.solver.max_iterations = 7;
  OdometryConfig command_line;  // defaults, except what the user typed
  command_line.voxel_size = 0.3;
  command_line.registration.solver.max_iterations = 12;
  const auto given = [](const std::string& flag) {
    return flag == "--voxel" || flag == "--max-iterations";
  };
  const OdometryConfig merged = override_given_flags(file, command_line, given);
  EXPECT_EQ(merged.voxel_size, 0.3);
  EXPECT_EQ(merged.registration.solver.max_iterations, 12);
  EXPECT_EQ(merged.map_radius, 30.0);  // from the file
  EXPECT_EQ(merged.method, file.method);
}

TEST(ConfigDescription, UnknownKeysAndBadKernelsNameTheKey) {
  try {
    odometry_config_from_json(R"({"registration": {"solver": {"kernal": "huber"}}})", "my.json");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("registration.solver.kernal"), std::string::npos)
        << e.what();
  }
  try {
    odometry_config_from_json(R"({"registration": {"solver": {"kernel": "l1"}}})", "my.json");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("my.json"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("registration.solver.kernel"), std::string::npos)
        << e.what();
  }
}

TEST(ConfigDescription, Map2DRunsReloadWithConfigAndGivenFlagsWin) {
  testing::TempDir dir;
  const std::string first = dir.file("first"), again = dir.file("again"), other = dir.file("other");
  const std::string common = "map2d sim:room-2d --scans 30 --quiet ";
  ASSERT_EQ(testing::run_cli(common + "--method pl-icp --search-angle 30 --out " + first).status,
            0);
  const Map2DRunOptions written = read_map2d_config(first + "/config.json");
  EXPECT_EQ(written.mapper.registration.method, "pl-icp");
  EXPECT_NEAR(written.mapper.registration.search_angle, 30 * M_PI / 180, 1e-12);
  EXPECT_DOUBLE_EQ(written.mapper.registration.search_window, 1.3);  // the mapper's default

  // The same configuration again gives the same poses; a flag given on top wins over the file.
  ASSERT_EQ(testing::run_cli(common + "--config " + first + "/config.json --out " + again).status,
            0);
  EXPECT_EQ(read_file_bytes(first + "/poses_tum.txt"), read_file_bytes(again + "/poses_tum.txt"));
  ASSERT_EQ(
      testing::run_cli(common + "--config " + first + "/config.json --method icp --out " + other)
          .status,
      0);
  const Map2DRunOptions overridden = read_map2d_config(other + "/config.json");
  EXPECT_EQ(overridden.mapper.registration.method, "icp");
  EXPECT_NEAR(overridden.mapper.registration.search_angle, 30 * M_PI / 180, 1e-12);

  testing::write_text(dir.file("bad.json"), R"({"mapper": {"registration": {"metod": "icp"}}})");
  const auto bad =
      testing::run_cli(common + "--config " + dir.file("bad.json") + " --out " + other);
  EXPECT_NE(bad.status, 0);
  EXPECT_NE(bad.output.find("mapper.registration.metod"), std::string::npos) << bad.output;
}

}  // namespace
}  // namespace scanmatch
