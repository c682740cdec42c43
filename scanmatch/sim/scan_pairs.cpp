#include "scanmatch/sim/scan_pairs.hpp"

#include <algorithm>
#include <cmath>

#include "scanmatch/core/error.hpp"
#include "scanmatch/io/trajectory.hpp"
#include "scanmatch/sim/random.hpp"
#include "scanmatch/sim/simulator.hpp"

namespace scanmatch::sim {
namespace {

double median_range(const LaserScan2D& scan) {
  std::vector<float> valid;
  for (float r : scan.ranges)
    if (r > 0.0f && r < scan.max_range) valid.push_back(r);
  if (valid.empty()) return 0.0;
  std::nth_element(valid.begin(), valid.begin() + static_cast<std::ptrdiff_t>(valid.size() / 2),
                   valid.end());
  return valid[valid.size() / 2];
}

}  // namespace

std::vector<PlanarScanPair> planar_scan_pairs(const PlanarPairOptions& options) {
  if (options.count == 0) return {};
  // The simulator replays a trajectory in which reference and current poses alternate, each
  // measured from its frame's start pose (no distortion). The replay is anchored at the scene's
  // loop start, so the first pose is that start and every later one is absolute.
  const World world = make_rooms_2d(options.seed);
  const Eigen::Vector2d start = world.loop.front();
  Rng rng(options.seed * 7919 + 17);
  Trajectory trajectory;
  trajectory.poses.push_back(from_xyz_rpy(start.x(), start.y(), 0, 0, 0, 0));
  // Two candidates per wanted pair: some land in furniture and are dropped after rendering.
  for (std::size_t k = 0; k < 2 * options.count; ++k) {
    const int room = static_cast<int>(rng.uniform(0, 3)) % 3;
    Eigen::Vector2d a;
    do {
      // One draw per statement (the order of a call's arguments is unspecified), as first built.
      const double y = rng.uniform(0.7, 3.3);
      a = Eigen::Vector2d(5.0 * room + rng.uniform(0.7, 4.3), y);
    } while (world.scene.distance_to_surface(Eigen::Vector3d(a.x(), a.y(), 0.2)) < 0.4);
    const double yaw = rng.uniform(-M_PI, M_PI);
    const double r = options.max_translation * std::sqrt(rng.uniform(0, 1));
    const double direction = rng.uniform(-M_PI, M_PI);
    const Eigen::Vector2d b = a + r * Eigen::Vector2d(std::cos(direction), std::sin(direction));
    const double yaw_b = yaw + rng.uniform(-options.max_rotation, options.max_rotation);
    trajectory.poses.push_back(from_xyz_rpy(a.x(), a.y(), 0, 0, 0, yaw));
    trajectory.poses.push_back(from_xyz_rpy(b.x(), b.y(), 0, 0, 0, yaw_b));
  }
  SimOptions o;
  o.preset = "room-2d";
  o.seed = options.seed;
  o.motion_distortion = false;
  o.noise = options.noise;
  o.frames = trajectory.size();
  o.trajectory = std::move(trajectory);
  const Simulator simulator(o);
  std::vector<PlanarScanPair> pairs;
  for (std::size_t i = 1; i + 1 < simulator.size() && pairs.size() < options.count; i += 2) {
    PlanarScanPair p{simulator.scan_2d(i), simulator.scan_2d(i + 1),
                     planar_pose(simulator.pose(i)).inverse() * planar_pose(simulator.pose(i + 1))};
    // Inside a piece of furniture every return is a few centimetres away.
    if (median_range(p.reference) < 0.8 || median_range(p.current) < 0.8) continue;
    pairs.push_back(std::move(p));
  }
  if (pairs.size() < options.count)
    throw Error("planar scan pairs: only " + std::to_string(pairs.size()) + " of " +
                std::to_string(options.count) + " usable pairs");
  return pairs;
}

}  // namespace scanmatch::sim
