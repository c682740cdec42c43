#include "scanmatch/odometry/run.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <unordered_set>

#include "scanmatch/core/error.hpp"
#include "scanmatch/core/progress.hpp"
#include "scanmatch/eval/metrics_json.hpp"
#include "scanmatch/geometry/voxel_key.hpp"
#include "scanmatch/io/cloud_io.hpp"
#include "scanmatch/io/file_util.hpp"
#include "scanmatch/io/trajectory.hpp"
#include "scanmatch/odometry/config_io.hpp"
#include "scanmatch/odometry/frame_odometry.hpp"

namespace scanmatch {
namespace {

// Appended and flushed a line at a time, like the trajectory writers.
class CsvWriter {
 public:
  CsvWriter(const std::string& path, const std::string& header) : path_(path) {
    file_ = std::fopen(path.c_str(), "w");
    if (!file_) fail(path, "cannot open for writing");
    line(header);
  }
  ~CsvWriter() {
    if (file_) std::fclose(file_);
  }
  CsvWriter(const CsvWriter&) = delete;
  CsvWriter& operator=(const CsvWriter&) = delete;
  void line(const std::string& text) {
    if (std::fputs(text.c_str(), file_) < 0 || std::fputc('\n', file_) == EOF ||
        std::fflush(file_) != 0)
      fail(path_, "write failed");
  }

 private:
  std::string path_;
  std::FILE* file_ = nullptr;
};

// The exported map: one point per cell of `voxel` metres, first come first kept, optionally only
// near the sensor. Bounded by the area the run covered, not by the number of frames.
class PointMap {
 public:
  explicit PointMap(double voxel) : voxel_(voxel) {}
  void add(const PointCloud& cloud, const Pose& pose) {
    for (const Point& p : cloud.points) {
      const Eigen::Vector3d w = pose * p.cast<double>();
      if (cells_.insert(voxel_key(w, voxel_)).second) points_.push_back(w.cast<float>());
    }
  }
  void keep_within(const Eigen::Vector3d& center, double radius) {
    const double r2 = radius * radius;
    std::vector<Point> kept;
    cells_.clear();
    for (const Point& p : points_) {
      if ((p.cast<double>() - center).squaredNorm() > r2) continue;
      cells_.insert(voxel_key(p.cast<double>(), voxel_));
      kept.push_back(p);
    }
    points_.swap(kept);
  }
  PointCloud cloud() const {
    PointCloud c;
    c.points = points_;
    return c;
  }

 private:
  double voxel_;
  std::unordered_set<VoxelKey, VoxelKeyHash> cells_;
  std::vector<Point> points_;
};

StageStatistics statistics(const std::vector<FrameStats>& stats, double FrameStats::*field) {
  StageStatistics s;
  if (stats.empty()) return s;
  for (const FrameStats& f : stats) {
    s.mean_ms += f.*field;
    s.max_ms = std::max(s.max_ms, f.*field);
  }
  s.mean_ms /= static_cast<double>(stats.size());
  return s;
}

nlohmann::ordered_json stage_json(const StageStatistics& s) {
  return {{"mean_ms", s.mean_ms}, {"max_ms", s.max_ms}};
}

// The keys of `scanmatch eval --json`.
// The ground truth of the frames run, and the estimate's ATE against it.
void evaluate(const std::optional<Trajectory>& truth, RunSummary& summary) {
  if (!truth || summary.frames == 0) return;
  const auto n = static_cast<std::ptrdiff_t>(std::min(summary.frames, truth->size()));
  summary.ground_truth.assign(truth->poses.begin(), truth->poses.begin() + n);
  summary.ate = compute_ate(summary.ground_truth,
                            std::vector<Pose>(summary.poses.begin(), summary.poses.begin() + n));
}

void write_ground_truth(const std::string& dir, const std::optional<Trajectory>& truth,
                        const RunSummary& summary) {
  if (summary.ground_truth.empty()) return;
  Trajectory gt;
  gt.poses = summary.ground_truth;
  if (truth->has_timestamps())
    gt.timestamps.assign(truth->timestamps.begin(),
                         truth->timestamps.begin() + static_cast<std::ptrdiff_t>(gt.size()));
  write_trajectory(dir + "/poses_gt.txt", gt, TrajectoryFormat::kKitti);
  if (gt.has_timestamps()) write_trajectory(dir + "/poses_gt_tum.txt", gt, TrajectoryFormat::kTum);
}

}  // namespace

RunSummary run_odometry(SequenceSource& source, const OdometryConfig& config,
                        const RunOptions& options) {
  const std::unique_ptr<FrameOdometry> odometry = make_frame_odometry(config);
  const std::optional<Trajectory> truth = source.ground_truth();
  RunSummary summary;
  summary.method = config.method;
  summary.source = source.describe();
  const bool write = !options.out_dir.empty();
  const std::string dir = options.out_dir;
  if (options.write_map && options.map_format != "pcd" && options.map_format != "ply")
    throw Error("map format must be pcd or ply (got '" + options.map_format + "')");
  if (!(options.map_voxel_size > 0.0)) throw Error("map export voxel size must be positive");
  std::unique_ptr<TrajectoryWriter> kitti, tum;
  std::unique_ptr<CsvWriter> timing;
  if (write) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) fail(dir, "cannot create the run folder: " + ec.message());
    write_file_atomic(dir + "/config.json", odometry_run_config_to_json({config, options}));
    kitti = std::make_unique<TrajectoryWriter>(dir + "/poses.txt", TrajectoryFormat::kKitti);
    tum = std::make_unique<TrajectoryWriter>(dir + "/poses_tum.txt", TrajectoryFormat::kTum);
    timing = std::make_unique<CsvWriter>(
        dir + "/timing.csv",
        "index,timestamp,preprocess_ms,coarse_ms,fine_ms,map_ms,total_ms,points_in,"
        "points_downsampled,iterations,condition_number,degenerate_directions,bridged");
  }
  const std::size_t total =
      options.max_frames > 0 ? std::min(options.max_frames, source.size()) : source.size();
  PointMap map(options.map_voxel_size);
  ProgressReporter progress("odometry " + config.method, total, "frames", options.quiet);
  Frame frame;
  double pipeline_ms = 0.0;
  while (summary.frames < total) {
    if (options.stop && options.stop->load()) {
      summary.interrupted = true;
      break;
    }
    try {
      if (!source.next(frame)) break;
    } catch (const Error& e) {
      summary.error = e.what();  // the run ends here, keeping what it finished
      break;
    }
    const Pose pose = odometry->register_frame(frame.cloud, frame.timestamp);
    const FrameStats& s = odometry->last_stats();
    pipeline_ms += s.total_ms;
    if (s.bridged && summary.frames > 0) {
      ++summary.bridged_frames;
      if (!options.quiet)
        std::fprintf(stderr, "odometry: frame %zu (%s): %s, bridged by the motion prior\n",
                     summary.frames, frame.name.c_str(),
                     s.points_downsampled < 20 ? "too few valid points" : "registration failed");
    }
    summary.poses.push_back(pose);
    summary.timestamps.push_back(frame.timestamp);
    summary.stats.push_back(s);
    if (write) {
      kitti->write(pose, frame.timestamp);
      tum->write(pose, frame.timestamp);
      timing->line(fmt::format("{},{:.6f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{},{},{},{:.6g},{},{}",
                               summary.frames, frame.timestamp, s.preprocess_ms, s.coarse_ms,
                               s.fine_ms, s.map_ms, s.total_ms, s.points_in, s.points_downsampled,
                               s.iterations, s.condition_number, s.degenerate_directions,
                               s.bridged ? 1 : 0));
    }
    // A bridged frame has no registered points of its own (an empty frame leaves the previous
    // one in last_frame()); it would only add a copy or a guess to the map.
    Pose world_from_frame;
    const PointCloud* map_frame =
        options.write_map && !s.bridged ? odometry->last_map_frame(world_from_frame) : nullptr;
    if (map_frame != nullptr) {
      map.add(*map_frame, world_from_frame);
      if (options.map_export_radius > 0.0 && summary.frames % 50 == 0)
        map.keep_within(pose.translation(), options.map_export_radius);
    }
    ++summary.frames;
    progress.update(summary.frames);
  }
  progress.finish();
  summary.preprocess = statistics(summary.stats, &FrameStats::preprocess_ms);
  summary.coarse = statistics(summary.stats, &FrameStats::coarse_ms);
  summary.fine = statistics(summary.stats, &FrameStats::fine_ms);
  summary.map_update = statistics(summary.stats, &FrameStats::map_ms);
  summary.total = statistics(summary.stats, &FrameStats::total_ms);
  summary.frames_per_second = pipeline_ms > 0.0 ? 1000.0 * summary.frames / pipeline_ms : 0.0;
  evaluate(truth, summary);

  if (write) {
    if (options.write_map) {
      if (options.map_export_radius > 0.0 && !summary.poses.empty())
        map.keep_within(summary.poses.back().translation(), options.map_export_radius);
      write_cloud(dir + "/map." + options.map_format, map.cloud());
    }
    write_ground_truth(dir, truth, summary);
    nlohmann::ordered_json j = {{"method", summary.method},
                                {"source", summary.source},
                                {"frames", summary.frames},
                                {"bridged_frames", summary.bridged_frames},
                                {"interrupted", summary.interrupted},
                                {"error", summary.error},
                                {"frames_per_second", summary.frames_per_second},
                                {"threads", config.threads},
                                {"stages",
                                 {{"preprocess", stage_json(summary.preprocess)},
                                  {"coarse", stage_json(summary.coarse)},
                                  {"fine", stage_json(summary.fine)},
                                  {"map_update", stage_json(summary.map_update)},
                                  {"total", stage_json(summary.total)}}}};
    if (summary.ate) j["ate"] = ate_json(*summary.ate);
    j["options"] = nlohmann::ordered_json::parse(odometry_config_to_json(config));
    write_file_atomic(dir + "/summary.json", j.dump(2) + "\n");
  }
  if (!summary.error.empty()) throw Error(summary.error);
  return summary;
}

}  // namespace scanmatch
