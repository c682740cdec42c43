#include "scanmatch/run/run_folder.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "scanmatch/core/error.hpp"
#include "scanmatch/io/file_util.hpp"
#include "scanmatch/io/record_csv.hpp"
#include "scanmatch/run/run_record.hpp"

namespace scanmatch {

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
  else if (fs::exists(path + "/poses_reference_tum.txt"))  // map2d: the log's corrected poses
    run.ground_truth = read_trajectory(path + "/poses_reference_tum.txt");
  const std::string timing = path + "/timing.csv";
  std::vector<std::string> header;  // timing.csv's columns
  if (fs::exists(timing)) {
    std::ifstream in(timing);
    std::string line;
    std::getline(in, line);
    header = record_csv_detail::split_cells(line);
  }
  bool kind_given = false;
  if (fs::exists(path + "/summary.json")) {
    try {
      const auto j = nlohmann::json::parse(read_file_bytes(path + "/summary.json"));
      run.method = j.value("method", std::string("?"));
      run.frames_per_second = j.value("frames_per_second", j.value("scans_per_second", 0.0));
      run.interrupted = j.value("interrupted", false);
      if (j.contains("kind")) {
        run.kind = j.at("kind").get<std::string>();
        kind_given = true;
      }
    } catch (const nlohmann::json::exception& e) {
      fail(path + "/summary.json", std::string("malformed: ") + e.what());
    }
    if (run.kind != kOdometryRunKind && run.kind != kMap2DRunKind)
      fail(path + "/summary.json", "unknown kind of run '" + run.kind + "'");
  }
  // Older folders (and runs that never wrote summary.json): map2d's timing.csv has no total_ms.
  if (!kind_given && !header.empty() &&
      std::find(header.begin(), header.end(), "total_ms") == header.end())
    run.kind = kMap2DRunKind;
  if (fs::exists(timing)) {
    if (run.kind == kOdometryRunKind)
      run.timing = read_timing_csv(timing);
    else if (header.empty() || header.front() != "scan")  // older "scan,ms,...": not read
      run.scan_timing = read_record_csv<Scan2DStats>(timing, "ms");
  }
  run.has_map = fs::exists(path + "/map.pcd");
  if (fs::exists(path + "/poses_optimized_tum.txt"))
    run.optimized = read_trajectory(path + "/poses_optimized_tum.txt");
  else if (fs::exists(path + "/poses_optimized.txt"))
    run.optimized = read_trajectory(path + "/poses_optimized.txt");
  if (fs::exists(path + "/loops.json")) {
    try {
      const auto j = nlohmann::json::parse(read_file_bytes(path + "/loops.json"));
      if (!j.is_array()) fail(path + "/loops.json", "expected an array of loop edges");
      const std::size_t frames = run.poses.size();
      for (const auto& edge : j) {
        const std::size_t from = edge.at("from").get<std::size_t>();
        const std::size_t to = edge.at("to").get<std::size_t>();
        if (from >= frames || to >= frames)
          fail(path + "/loops.json", "loop edge " + std::to_string(from) + " -> " +
                                         std::to_string(to) + " names a frame past the run's " +
                                         std::to_string(frames));
        run.loops.emplace_back(from, to);
      }
    } catch (const nlohmann::json::exception& e) {
      fail(path + "/loops.json", std::string("malformed: ") + e.what());
    }
  }
  return run;
}

}  // namespace scanmatch
