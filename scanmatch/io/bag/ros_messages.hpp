#pragma once
// Decoding the bag messages scanmatch uses, in ROS 1 serialization (packed little endian) or ROS 2
// CDR (a 4-byte encapsulation header, then values aligned to their size from the header's end):
//   sensor_msgs/PointCloud2       -> PointCloud, any field layout; x y z required; intensity from
//                                    "intensity" (else "reflectivity"), ring from "ring"/"line",
//                                    per-point time from "t" or "offset_time" (integer ns) or
//                                    "time"/"timestamp" (float s; integer ns); absolute times
//                                    (above 1e6 s) are made relative to the earliest point.
//   livox_ros_driver(2)/CustomMsg -> PointCloud with reflectivity, line and offset_time.
//   sensor_msgs/LaserScan         -> LaserScan2D.
// Points with a non-finite coordinate are dropped. Errors name the file, topic and byte.

#include <cstdint>
#include <string>
#include <string_view>

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/io/bag/bag.hpp"
#include "scanmatch/io/carmen.hpp"

namespace scanmatch {

enum class RosMessageType { kPointCloud2, kLivoxCustom, kLaserScan, kOther };

/// From a type name in ROS 1 ("sensor_msgs/PointCloud2") or ROS 2 ("sensor_msgs/msg/PointCloud2")
/// spelling.
RosMessageType ros_message_type(std::string_view type);

/// True for the types decode_cloud_message understands.
inline bool is_cloud_type(std::string_view type) {
  const RosMessageType t = ros_message_type(type);
  return t == RosMessageType::kPointCloud2 || t == RosMessageType::kLivoxCustom;
}

/// Decodes a PointCloud2 or Livox CustomMsg; `stamp_ns` (optional) receives the header stamp.
/// Throws Error naming `source`, the topic and the byte for other types and malformed data.
PointCloud decode_cloud_message(const BagMessage& message, const std::string& source,
                                std::int64_t* stamp_ns = nullptr);

/// Decodes a LaserScan: angles, range_max, ranges, intensities (as remissions) and the header
/// stamp as the timestamp (s). Throws Error as decode_cloud_message does.
LaserScan2D decode_laser_scan(const BagMessage& message, const std::string& source);

}  // namespace scanmatch
