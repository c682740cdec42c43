#pragma once
// One interface for every odometry the runner and the benchmark drive: ours (CtfIcpOdometry,
// FrameToFrameOdometry for every registration method; odometry.hpp) and the optional peers built
// beside it (PCL's ICP, NDT and GICP, KISS-ICP; peers/ at the repository root, CMake options
// SCANMATCH_WITH_PCL and SCANMATCH_WITH_KISS). A peer registers itself by name at start-up; the
// core library never depends on one.

#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/core/se3.hpp"
#include "scanmatch/odometry/frame_stats.hpp"
#include "scanmatch/odometry/odometry_config.hpp"

namespace scanmatch {

/// Fewer points than this (in a frame, or paired by a stage) make a registration unusable: the
/// frame is bridged by the motion prior.
constexpr std::size_t kMinimumFramePoints = 20;

class FrameOdometry {
 public:
  virtual ~FrameOdometry() = default;
  /// Registers the next frame (sensor frame, point times in s from the frame start when present);
  /// returns its pose in the world frame of frame 0.
  virtual Pose register_frame(const PointCloud& frame, double timestamp) = 0;
  /// Timing and counts of the last frame (stages a method does not have stay 0).
  virtual const FrameStats& last_stats() const = 0;
  /// The last registered frame's points for the exported map, and the pose that places them in
  /// the method's registration frame; nullptr when the method keeps none.
  virtual const PointCloud* last_map_frame(Pose& registration_from_frame) const = 0;
  /// Places the registration frame in the world frame of the reported poses. Identity for a method
  /// that registers in that world; ours registers from frame 0's middle, and the world (frame 0's
  /// start) is known from the first motions: it may move until `world_settles_after` frames.
  virtual Pose world_from_registration() const { return Pose::Identity(); }
  virtual std::size_t world_settles_after() const { return 0; }
  /// The pose of frame `index` (< world_settles_after()) in the world as it stands now: the frames
  /// before the world settles were returned in a provisional one.
  virtual Pose settled_pose(std::size_t /*index*/) const { return Pose::Identity(); }
  /// Frame 0's points as the odometry settled them (deskewed once the first motion was known),
  /// at the registration frame's origin, until the world settles; nullptr where last_map_frame()
  /// at frame 0 gave them as they stay.
  virtual const PointCloud* settled_first_frame() const { return nullptr; }
};

/// Replaces the poses of the frames before `odometry`'s world settles (poses[i]: frame i as
/// register_frame returned it) with their poses in the world as it stands (settled once
/// world_settles_after() frames are registered); the runner, Python's Odometry and the tests
/// report frames through it.
void settle_early_poses(const FrameOdometry& odometry, std::vector<Pose>& poses);

/// Builds a peer from the run's configuration (the peer reads what applies to it: voxel_size,
/// ranges, threads).
using PeerFactory = std::function<std::unique_ptr<FrameOdometry>(const OdometryConfig&)>;

/// Makes `name` a method of make_frame_odometry; peers call it from a static initialiser.
/// Returns true (so it can initialise a namespace-scope constant).
bool register_odometry_peer(const std::string& name, const std::string& description,
                            PeerFactory factory);

/// The odometry for config.method: a registered peer, or ours (make_odometry_pipeline). Throws
/// Error for an unknown method, naming the CMake option that builds a known peer this build lacks.
std::unique_ptr<FrameOdometry> make_frame_odometry(const OdometryConfig& config);

/// Throws what make_frame_odometry would for an unusable method, without building anything.
void check_odometry_method(const std::string& method);

/// Peers built into this program, "name: description" each.
std::vector<std::string> odometry_peers();

/// odometry_method_list() plus the peers built in.
std::string odometry_methods_with_peers();

/// Every peer this project knows (built into this program or not), by name.
std::vector<std::string> known_odometry_peers();

/// For a peer this project knows but this build lacks, the CMake option that builds it; empty
/// for a peer that is built, for our own methods and for unknown names.
std::string missing_peer_option(const std::string& method);

}  // namespace scanmatch
