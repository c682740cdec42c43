#pragma once
// The one place that turns a sequence spec into a SequenceSource: every command and the benchmark
// open their input here, never a reader of their own. It lives in sim/ because that is the lowest
// folder that sees the folder readers (io/), bags (io/bag/) and the simulator.

#include <memory>
#include <string>

#include "scanmatch/io/cloud_io.hpp"
#include "scanmatch/io/sequence.hpp"
#include "scanmatch/sim/simulator.hpp"

namespace scanmatch {

struct SequenceOptions {
  /// Bags: the PointCloud2 or Livox CustomMsg topic (empty: the bag's only cloud topic).
  std::string topic;
  /// `sim:PRESET`: seed, frames, sensor, noise... (the preset is replaced by PRESET).
  sim::SimOptions simulator;
  /// Folders and KITTI sequences: how each frame file is read.
  CloudReadOptions cloud;
  /// A trajectory file (KITTI 3x4 or TUM rows, one pose per frame) used as the ground truth in
  /// place of the source's own, e.g. a SLAM reference kept beside a folder of frames. Empty: the
  /// source's own (poses.txt of a KITTI sequence, poses_gt.txt of a data set, the simulator's).
  /// Its poses are re-expressed in the frame of its first pose, as the run's poses are.
  /// A KITTI file has no times, so the run writes no poses_gt_tum.txt for it.
  std::string reference;
  /// 2D CARMEN logs: FLASER scans take the log's own no-return reading for their maximum range
  /// (CarmenReadOptions::infer_no_return).
  bool infer_no_return = true;
};

/// Opens `spec`:
///   sim:PRESET                 frames simulated on the fly (options.simulator)
///   a .bag, .db3 or .mcap file (or a ROS 2 bag folder)   the point clouds of options.topic
///   a folder                   a KITTI sequence, a simulated data set or frame files, as
///                              open_sequence_folder (scanmatch/io/sequence.hpp) reads it
/// Throws Error naming `spec` when it does not exist ("no such sequence"), holds no frames, or
/// the reference's pose count differs from the frame count.
std::unique_ptr<SequenceSource> open_sequence(const std::string& spec,
                                              const SequenceOptions& options = {});

/// A reference trajectory kept beside a folder's frames under a name the folder reader does not
/// take as ground truth itself: FOLDER/odom_poses.txt (as SLAM pipelines save their odometry) or
/// FOLDER/reference_poses.txt. Its path, or empty when `spec` is not a folder or holds neither.
/// For SequenceOptions::reference where the source has no ground truth of its own.
std::string reference_beside(const std::string& spec);

/// True for `sim:PRESET` specs.
bool is_simulator_spec(const std::string& spec);

}  // namespace scanmatch
