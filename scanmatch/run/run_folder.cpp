#include "scanmatch/run/run_folder.hpp"

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "scanmatch/core/error.hpp"
#include "scanmatch/io/file_util.hpp"

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
  // map2d's timing.csv (one row per scan: scan,ms,...) has none of the 3D stages or health
  // fields; its runs are shown without the per-frame plots.
  const std::string timing = path + "/timing.csv";
  if (fs::exists(timing)) {
    std::ifstream in(timing);
    std::string header;
    std::getline(in, header);
    if (header.rfind("scan,ms,", 0) != 0) run.timing = read_timing_csv(timing);
  }
  if (fs::exists(path + "/summary.json")) {
    try {
      const auto j = nlohmann::json::parse(read_file_bytes(path + "/summary.json"));
      run.method = j.value("method", std::string("?"));
      run.frames_per_second = j.value("frames_per_second", j.value("scans_per_second", 0.0));
      run.interrupted = j.value("interrupted", false);
    } catch (const nlohmann::json::exception& e) {
      fail(path + "/summary.json", std::string("malformed: ") + e.what());
    }
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
