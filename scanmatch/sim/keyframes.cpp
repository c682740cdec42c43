#include "scanmatch/sim/keyframes.hpp"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <numeric>

#include "scanmatch/core/error.hpp"
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
  if (sim.sensor().is_2d())
    throw Error("simulate: keyframe options are for 3D sensors ('" + sim.sensor().name +
                "' is 2D)");
  DatasetSelection selection;
  selection.frames = select_keyframes(sim, o);
  selection.prepare = [&](PointCloud cloud, std::size_t i) {
    return thin_keyframe(std::move(cloud), o, i);
  };
  selection.describe = [&](nlohmann::ordered_json& info) {
    info["keyframes"] = {{"source_frames", sim.size()},
                         {"every", o.every},
                         {"distance_m", o.distance},
                         {"distance_max_m", o.distance_max},
                         {"angle_rad", o.angle},
                         {"max_points", o.max_points},
                         {"point_time", o.point_time},
                         {"seed", o.seed},
                         {"frame_indices", selection.frames}};
  };
  write_dataset(sim, folder, quiet, selection);
}

}  // namespace scanmatch::sim
