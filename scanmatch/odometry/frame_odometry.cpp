#include "scanmatch/odometry/frame_odometry.hpp"

#include <algorithm>
#include <map>

#include "scanmatch/core/error.hpp"
#include "scanmatch/odometry/odometry.hpp"
#include "scanmatch/odometry/odometry_pipeline.hpp"

namespace scanmatch {
namespace {

struct Peer {
  std::string description;
  PeerFactory factory;
};

// Function-local so that peers registering from other translation units' static initialisers
// find it constructed.
std::map<std::string, Peer>& peers() {
  static std::map<std::string, Peer> registry;
  return registry;
}

/// Peers this project knows, with the CMake option that builds them.
struct KnownPeer {
  const char* name;
  const char* option;
};
constexpr KnownPeer kKnownPeers[] = {
    {"pcl-icp", "-DSCANMATCH_WITH_PCL=ON (Debian libpcl-dev: scripts/bootstrap --pcl)"},
    {"pcl-ndt", "-DSCANMATCH_WITH_PCL=ON (Debian libpcl-dev: scripts/bootstrap --pcl)"},
    {"pcl-gicp", "-DSCANMATCH_WITH_PCL=ON (Debian libpcl-dev: scripts/bootstrap --pcl)"},
    {"kiss-icp", "-DSCANMATCH_WITH_KISS=ON (KISS-ICP installed; docs/benchmarks.md, Peers)"},
};

}  // namespace

void settle_early_poses(const FrameOdometry& odometry, std::vector<Pose>& poses) {
  for (std::size_t i = 0; i < std::min(poses.size(), odometry.world_settles_after()); ++i)
    poses[i] = odometry.settled_pose(i);
}

bool register_odometry_peer(const std::string& name, const std::string& description,
                            PeerFactory factory) {
  peers()[name] = Peer{description, std::move(factory)};
  return true;
}

std::vector<std::string> known_odometry_peers() {
  std::vector<std::string> names;
  for (const KnownPeer& known : kKnownPeers) names.emplace_back(known.name);
  return names;
}

std::string missing_peer_option(const std::string& method) {
  if (peers().count(method) > 0) return "";
  for (const KnownPeer& known : kKnownPeers)
    if (method == known.name) return known.option;
  return "";
}

void check_odometry_method(const std::string& method) {
  if (const std::string option = missing_peer_option(method); !option.empty())
    throw Error("odometry method '" + method +
                "' is a peer this build does not have: configure with " + option);
  if (peers().count(method) > 0) return;
  if (!is_odometry_method(method))
    throw Error("unknown odometry method '" + method +
                "' (valid: " + odometry_methods_with_peers() + ")");
}

std::unique_ptr<FrameOdometry> make_frame_odometry(const OdometryConfig& config) {
  check_odometry_method(config.method);
  if (const auto it = peers().find(config.method); it != peers().end())
    return it->second.factory(config);
  return make_odometry_pipeline(config);
}

std::vector<std::string> odometry_peers() {
  std::vector<std::string> out;
  for (const auto& [name, peer] : peers()) out.push_back(name + ": " + peer.description);
  return out;
}

std::string odometry_methods_with_peers() {
  std::string list = odometry_method_list();
  for (const auto& [name, peer] : peers()) list += ", " + name;
  return list;
}

}  // namespace scanmatch
