// `scanmatch info FILE|FOLDER`: what a file or folder holds. Clouds by extension (.pcd .ply .bin
// .xyz .csv); a .txt whose first data line has 12 or 8 numbers is a trajectory (KITTI or TUM),
// otherwise a text cloud; .log files are CARMEN logs; folders are sequences; .bag, .db3 and .mcap
// files (and ROS 2 bag folders) are bags: their topics, types and message counts.

#include <fmt/format.h>

#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>

#include "apps/commands.hpp"
#include "apps/file_kind.hpp"
#include "scanmatch/io/bag/bag.hpp"
#include "scanmatch/io/carmen.hpp"
#include "scanmatch/io/cloud_io.hpp"
#include "scanmatch/io/trajectory.hpp"
#include "scanmatch/sim/open_sequence.hpp"

namespace scanmatch::cli {
namespace {

nlohmann::ordered_json cloud_info(const std::string& path) {
  CloudFileInfo info;
  CloudReadOptions options;
  options.keep_non_finite = false;
  const PointCloud cloud = read_cloud(path, options, &info);
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(std::numeric_limits<float>::max());
  Eigen::Vector3f hi = -lo;
  for (const Point& p : cloud.points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  nlohmann::ordered_json j = {{"kind", "cloud"},
                              {"format", to_string(info.format)},
                              {"encoding", info.encoding},
                              {"gzip", info.compressed_gzip},
                              {"points", cloud.size()},
                              {"points_in_file", info.points_in_file},
                              {"non_finite", info.non_finite},
                              {"fields", info.fields},
                              {"width", info.width},
                              {"height", info.height}};
  if (!cloud.empty()) {
    j["min"] = {lo.x(), lo.y(), lo.z()};
    j["max"] = {hi.x(), hi.y(), hi.z()};
  }
  return j;
}

nlohmann::ordered_json trajectory_info(const std::string& path) {
  const Trajectory t = read_trajectory(path);
  nlohmann::ordered_json j = {{"kind", "trajectory"},
                              {"format", t.has_timestamps() ? "TUM" : "KITTI"},
                              {"poses", t.size()},
                              {"path_length_m", t.path_length()}};
  if (t.has_timestamps()) j["duration_s"] = t.timestamps.back() - t.timestamps.front();
  return j;
}

nlohmann::ordered_json carmen_info(const std::string& path) {
  const CarmenLog log = read_carmen_log(path);
  std::size_t min_beams = std::numeric_limits<std::size_t>::max(), max_beams = 0;
  double path_length = 0.0;
  for (std::size_t i = 0; i < log.scans.size(); ++i) {
    min_beams = std::min(min_beams, log.scans[i].ranges.size());
    max_beams = std::max(max_beams, log.scans[i].ranges.size());
    if (i > 0)
      path_length += (log.scans[i].pose.head<2>() - log.scans[i - 1].pose.head<2>()).norm();
  }
  nlohmann::ordered_json j = {{"kind", "CARMEN log"},
                              {"laser_scans", log.scans.size()},
                              {"odometry_records", log.odometry.size()},
                              {"other_records", log.ignored_lines},
                              {"reference_path_length_m", path_length}};
  if (!log.scans.empty()) {
    j["beams_min"] = min_beams;
    j["beams_max"] = max_beams;
    j["duration_s"] = log.scans.back().timestamp - log.scans.front().timestamp;
  }
  return j;
}

nlohmann::ordered_json sequence_info(const std::string& path) {
  const auto sequence = open_sequence(path);
  nlohmann::ordered_json j = {{"kind", "sequence"},
                              {"description", sequence->describe()},
                              {"frames", sequence->size()},
                              {"ground_truth", static_cast<bool>(sequence->ground_truth())}};
  if (const auto gt = sequence->ground_truth()) j["ground_truth_path_length_m"] = gt->path_length();
  return j;
}

nlohmann::ordered_json bag_info(const std::string& path) {
  const auto bag = open_bag(path);
  nlohmann::ordered_json topics = nlohmann::ordered_json::array();
  for (const BagTopic& t : bag->topics())
    topics.push_back({{"name", t.name},
                      {"type", t.type},
                      {"encoding", t.encoding},
                      {"messages", t.message_count}});
  nlohmann::ordered_json j = {{"kind", "bag"}, {"format", bag->format()}, {"topics", topics}};
  if (bag->fault()) j["fault"] = *bag->fault();
  return j;
}

void print_plain(const nlohmann::ordered_json& j) {
  for (const auto& [key, value] : j.items()) {
    if (key == "topics" && value.is_array()) {  // one line per bag topic
      fmt::print("topics: {}\n", value.size());
      for (const auto& t : value)
        fmt::print("  {}  {}  {}  {} messages\n", t["name"].get<std::string>(),
                   t["type"].get<std::string>(), t["encoding"].get<std::string>(),
                   t["messages"].get<std::uint64_t>());
    } else if (value.is_string())
      fmt::print("{}: {}\n", key, value.get<std::string>());
    else
      fmt::print("{}: {}\n", key, value.dump());
  }
}

}  // namespace

void add_info_command(CLI::App& app) {
  auto path = std::make_shared<std::string>();
  auto json = std::make_shared<bool>(false);
  auto* cmd = app.add_subcommand(
      "info", "Describe a point cloud, trajectory, CARMEN log, sequence folder or bag");
  cmd->add_option("PATH", *path, "File or folder")->required();
  cmd->add_flag("--json", *json, "Print JSON");
  cmd->callback([path, json] {
    nlohmann::ordered_json j;
    switch (detect_file_kind(*path)) {
      case FileKind::kCloud:  // .bag, .db3 and .mcap have no cloud extension
        j = is_bag_path(*path) ? bag_info(*path) : cloud_info(*path);
        break;
      case FileKind::kTrajectory:
        j = trajectory_info(*path);
        break;
      case FileKind::kCarmen:
        j = carmen_info(*path);
        break;
      case FileKind::kSequence:  // or a ROS 2 bag folder
        j = is_bag_path(*path) ? bag_info(*path) : sequence_info(*path);
        break;
    }
    j["path"] = *path;
    if (*json)
      fmt::print("{}\n", j.dump(2));
    else
      print_plain(j);
  });
}

}  // namespace scanmatch::cli
