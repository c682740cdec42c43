#include "scanmatch/sim/keyframes.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <numeric>

#include "scanmatch/core/error.hpp"
#include "scanmatch/core/progress.hpp"
#include "scanmatch/io/cloud_io.hpp"
#include "scanmatch/io/file_util.hpp"
#include "scanmatch/sim/random.hpp"

namespace scanmatch::sim {
namespace {
// Separate random streams for the thresholds and the subsampling (and apart from the rays').
constexpr std::uint64_t kThresholdStream = 0x6b657966'74687265ull;
constexpr std::uint64_t kSubsampleStream = 0x6b657966'73756273ull;
}  // namespace

bool KeyframeOptions::active() const {
  return every > 1 || distance > 0.0 || angle > 0.0 || max_points > 0 || !point_time;
}

void check_keyframe_options(const KeyframeOptions& o) {
  if (o.every == 0) throw Error("simulate: --every must be at least 1");
  if (!(o.distance >= 0.0) || !std::isfinite(o.distance))
    throw Error("simulate: --keyframe-distance must not be negative");
  if (o.distance_max != 0.0 && (!(o.distance_max >= o.distance) || !std::isfinite(o.distance_max)))
    throw Error("simulate: --keyframe-distance-max must be at least --keyframe-distance");
  if (o.distance_max > 0.0 && o.distance == 0.0)
    throw Error("simulate: --keyframe-distance-max needs --keyframe-distance");
  if (!(o.angle >= 0.0) || !std::isfinite(o.angle))
    throw Error("simulate: --keyframe-angle must not be negative");
}

std::vector<std::size_t> select_keyframes(const Simulator& simulator, const KeyframeOptions& o) {
  check_keyframe_options(o);
  const bool by_motion = o.distance > 0.0 || o.angle > 0.0;
  Rng rng(hash_combine(o.seed, kThresholdStream));
  const auto draw_distance = [&] {
    return o.distance_max > o.distance ? rng.uniform(o.distance, o.distance_max) : o.distance;
  };
  std::vector<std::size_t> kept = {0};
  Pose last = simulator.pose(0);
  double threshold = draw_distance();
  for (std::size_t i = o.every; i < simulator.size(); i += o.every) {
    if (by_motion) {
      const Pose pose = simulator.pose(i);
      const Pose motion = last.inverse() * pose;
      const bool far = o.distance > 0.0 && motion.translation().norm() >= threshold;
      const bool turned = o.angle > 0.0 && rotation_angle(motion) >= o.angle;
      if (!far && !turned) continue;
      last = pose;
      threshold = draw_distance();
    }
    kept.push_back(i);
  }
  return kept;
}

PointCloud thin_keyframe(PointCloud cloud, const KeyframeOptions& o, std::size_t index) {
  if (o.max_points > 0 && cloud.size() > o.max_points) {
    // Partial Fisher-Yates: the first max_points entries are a uniform random subset.
    std::vector<std::size_t> order(cloud.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    Rng rng(hash_combine(hash_combine(o.seed, kSubsampleStream), index));
    for (std::size_t k = 0; k < o.max_points; ++k) {
      const std::size_t pick =
          k + static_cast<std::size_t>(rng.uniform() * static_cast<double>(order.size() - k));
      std::swap(order[k], order[std::min(pick, order.size() - 1)]);
    }
    order.resize(o.max_points);
    std::sort(order.begin(), order.end());
    cloud = select(cloud, order);
  }
  if (!o.point_time) cloud.time.clear();
  return cloud;
}

void write_keyframe_dataset(const Simulator& sim, const KeyframeOptions& o,
                            const std::string& folder, bool quiet) {
  namespace fs = std::filesystem;
  if (sim.sensor().is_2d())
    throw Error("simulate: keyframe options are for 3D sensors ('" + sim.sensor().name +
                "' is 2D)");
  const std::vector<std::size_t> kept = select_keyframes(sim, o);
  std::error_code ec;
  fs::create_directories(fs::path(folder) / "frames", ec);
  if (ec) throw Error(folder + ": cannot create the folder: " + ec.message());
  ProgressReporter progress("simulate " + sim.preset().name + " keyframes", kept.size(), "frames",
                            quiet);
  TrajectoryWriter kitti((fs::path(folder) / "poses_gt.txt").string(), TrajectoryFormat::kKitti);
  TrajectoryWriter tum((fs::path(folder) / "poses_gt_tum.txt").string(), TrajectoryFormat::kTum);
  std::string times;
  std::size_t points = 0;
  double path = 0.0;
  for (std::size_t k = 0; k < kept.size(); ++k) {
    const std::size_t i = kept[k];
    const PointCloud cloud = thin_keyframe(sim.frame(i), o, i);
    points += cloud.size();
    char name[32];
    std::snprintf(name, sizeof name, "%06zu.pcd", i);
    write_cloud((fs::path(folder) / "frames" / name).string(), cloud);
    kitti.write(sim.pose(i), sim.frame_time(i));
    tum.write(sim.pose(i), sim.frame_time(i));
    char line[64];
    std::snprintf(line, sizeof line, "%.6f\n", sim.frame_time(i));
    times += line;
    if (k > 0) path += (sim.pose(i).translation() - sim.pose(kept[k - 1]).translation()).norm();
    progress.update(k + 1);
  }
  progress.finish();
  write_file_atomic((fs::path(folder) / "times.txt").string(), times);
  const nlohmann::ordered_json info = {{"preset", sim.preset().name},
                                       {"scene", sim.preset().scene},
                                       {"sensor", sim.sensor().name},
                                       {"rate_hz", sim.sensor().rate_hz},
                                       {"seed", sim.options().seed},
                                       {"frames", kept.size()},
                                       {"path_length_m", path},
                                       {"motion_distortion", sim.options().motion_distortion},
                                       {"noise", sim.options().noise},
                                       {"points", points},
                                       {"description", sim.preset().description},
                                       {"keyframes",
                                        {{"source_frames", sim.size()},
                                         {"every", o.every},
                                         {"distance_m", o.distance},
                                         {"distance_max_m", o.distance_max},
                                         {"angle_rad", o.angle},
                                         {"max_points", o.max_points},
                                         {"point_time", o.point_time},
                                         {"seed", o.seed},
                                         {"frame_indices", kept}}}};
  write_file_atomic((fs::path(folder) / "dataset.json").string(), info.dump(2) + "\n");
}

}  // namespace scanmatch::sim
