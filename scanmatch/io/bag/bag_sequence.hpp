#pragma once
// Bags as inputs of the pipelines: the point clouds of one topic as a SequenceSource (odometry)
// and the laser scans of one topic as LaserScan2Ds (map2d).

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "scanmatch/io/bag/bag.hpp"
#include "scanmatch/io/bag/ros_messages.hpp"
#include "scanmatch/io/carmen.hpp"
#include "scanmatch/io/sequence.hpp"

namespace scanmatch {

/// The topic to read: `topic` when given (it must exist and have a type `accept` takes), else the
/// one topic of such a type. Throws Error naming the file and listing the candidates otherwise.
/// `what` names the wanted kind in messages ("point cloud").
std::string choose_bag_topic(const BagReader& bag, const std::string& topic,
                             bool (*accept)(std::string_view type), const std::string& what);

/// The PointCloud2 or Livox CustomMsg frames of `topic` (empty: the bag's only cloud topic), in
/// time order, with per-point time where the messages have it. Frame timestamps are the header
/// stamps, s. Frames before a fault (truncated file, malformed message) are delivered; next()
/// then throws the Error (size() counts the fault as one more frame, so that it is met).
std::unique_ptr<SequenceSource> open_bag_sequence(const std::string& path,
                                                  const std::string& topic = "");

/// The sensor_msgs/LaserScan messages of `topic` (empty: the bag's only scan topic), in time
/// order; at most `max_scans` (0: all). Poses are zero (bags hold no reference). Throws Error.
std::vector<LaserScan2D> read_bag_laser_scans(const std::string& path,
                                              const std::string& topic = "",
                                              std::size_t max_scans = 0);

}  // namespace scanmatch
