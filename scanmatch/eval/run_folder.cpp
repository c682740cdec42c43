#include "scanmatch/eval/run_folder.hpp"

#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>

#include "scanmatch/core/error.hpp"
#include "scanmatch/io/file_util.hpp"

namespace scanmatch {
namespace {

std::vector<FrameTiming> parse_timing(const std::string& path) {
  std::istringstream in(read_file_bytes(path));
  std::string line;
  if (!std::getline(in, line)) fail(path, "empty file");
  std::vector<std::string> header;
  {
    std::istringstream h(line);
    for (std::string cell; std::getline(h, cell, ',');) header.push_back(cell);
  }
  const auto column = [&](const std::string& name) {
    for (std::size_t i = 0; i < header.size(); ++i)
      if (header[i] == name) return static_cast<int>(i);
    return -1;
  };
  const int timestamp = column("timestamp"), pre = column("preprocess_ms"),
            coarse = column("coarse_ms"), fine = column("fine_ms"), map = column("map_ms"),
            total = column("total_ms"), iterations = column("iterations"),
            condition = column("condition_number"), degenerate = column("degenerate_directions"),
            bridged = column("bridged");
  if (total < 0) fail(path, "line 1", "no total_ms column");
  std::vector<FrameTiming> rows;
  std::size_t number = 1;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty()) continue;
    std::vector<double> v;
    std::istringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');) {
      try {
        v.push_back(std::stod(cell));
      } catch (const std::exception&) {
        fail(path, "line " + std::to_string(number), "not a number: '" + cell + "'");
      }
    }
    if (v.size() != header.size())
      fail(path, "line " + std::to_string(number),
           "expected " + std::to_string(header.size()) + " values, found " +
               std::to_string(v.size()));
    const auto get = [&](int c) { return c >= 0 ? v[static_cast<std::size_t>(c)] : 0.0; };
    FrameTiming t;
    t.timestamp = get(timestamp);
    t.preprocess_ms = get(pre);
    t.coarse_ms = get(coarse);
    t.fine_ms = get(fine);
    t.map_ms = get(map);
    t.total_ms = get(total);
    t.iterations = static_cast<int>(get(iterations));
    t.condition_number = get(condition);
    t.degenerate_directions = static_cast<int>(get(degenerate));
    t.bridged = get(bridged) != 0.0;
    rows.push_back(t);
  }
  return rows;
}

}  // namespace

RunFolder read_run_folder(const std::string& path) {
  namespace fs = std::filesystem;
  if (!fs::is_directory(path)) fail(path, "not a run folder (no such directory)");
  RunFolder run;
  run.path = path;
  run.label = fs::path(path).lexically_normal().filename().string();
  if (run.label.empty()) run.label = fs::path(path).lexically_normal().parent_path().filename();
  const std::string poses = path + "/poses.txt", tum = path + "/poses_tum.txt";
  if (fs::exists(tum))
    run.poses = read_trajectory(tum);
  else if (fs::exists(poses))
    run.poses = read_trajectory(poses);
  else
    fail(path, "no poses.txt or poses_tum.txt: not a run folder of scanmatch odometry");
  if (fs::exists(path + "/poses_gt_tum.txt"))
    run.ground_truth = read_trajectory(path + "/poses_gt_tum.txt");
  else if (fs::exists(path + "/poses_gt.txt"))
    run.ground_truth = read_trajectory(path + "/poses_gt.txt");
  if (fs::exists(path + "/timing.csv")) run.timing = parse_timing(path + "/timing.csv");
  run.method = "?";
  if (fs::exists(path + "/summary.json")) {
    try {
      const auto j = nlohmann::json::parse(read_file_bytes(path + "/summary.json"));
      run.method = j.value("method", std::string("?"));
      run.frames_per_second = j.value("frames_per_second", 0.0);
      run.interrupted = j.value("interrupted", false);
    } catch (const nlohmann::json::exception& e) {
      fail(path + "/summary.json", std::string("malformed: ") + e.what());
    }
  }
  run.has_map = fs::exists(path + "/map.pcd");
  return run;
}

}  // namespace scanmatch
