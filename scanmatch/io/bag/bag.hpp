#pragma once
// ROS recordings: ROS 1 bags (format 2.0; chunks uncompressed, bz2 or lz4), ROS 2 SQLite bags
// (.db3) and MCAP files (ROS 2 "cdr" or ROS 1 "ros1" messages; chunks uncompressed, zstd or lz4).
// One interface lists the topics and walks the raw messages of chosen topics in time order;
// ros_messages.hpp decodes point clouds and laser scans from them.
//
// Index records are not needed: ROS 1 bags and MCAP files are read record by record. A fault
// after the first messages (a recording cut short, a corrupt chunk) does not stop the messages
// before it: open_bag succeeds, fault() tells, and next() throws it after the last good message.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace scanmatch {

struct BagTopic {
  std::string name;
  std::string type;  ///< as recorded: "sensor_msgs/PointCloud2" or "sensor_msgs/msg/PointCloud2"
  std::string encoding;  ///< message serialization: "ros1", "cdr" (others are listed, not decoded)
  std::uint64_t message_count = 0;
};

struct BagMessage {
  std::int64_t timestamp_ns = 0;  ///< when the recorder received it (ROS 1 record time, MCAP
                                  ///< log time, db3 timestamp), ns since the epoch
  std::string topic, type, encoding;
  std::string data;   ///< the serialized message
  std::string where;  ///< its place in the file, for errors: "byte 4096" or "chunk at byte ..."
};

class BagReader {
 public:
  virtual ~BagReader() = default;
  /// Every topic of the bag, sorted by name.
  const std::vector<BagTopic>& topics() const { return topics_; }
  const std::string& path() const { return path_; }
  /// "ROS 1 bag", "ROS 2 SQLite bag" or "MCAP".
  virtual std::string format() const = 0;
  /// Restricts next() to these topics (all when empty) and restarts from the earliest message.
  /// Throws Error naming the file and topic when the bag has no such topic.
  virtual void select(const std::vector<std::string>& topics) = 0;
  /// The next selected message in time order (ties in file order); false after the last. Throws
  /// Error (naming the file and byte offset) once the messages before a fault are delivered.
  virtual bool next(BagMessage& message) = 0;
  /// The problem that ended the readable part of the file early, if any.
  const std::optional<std::string>& fault() const { return fault_; }
  /// The topic named `name`; nullptr when absent.
  const BagTopic* find_topic(const std::string& name) const;

 protected:
  /// Throws Error for names the bag lacks, listing its topics.
  void check_topics(const std::vector<std::string>& names) const;
  std::string path_;
  std::vector<BagTopic> topics_;
  std::optional<std::string> fault_;
};

/// Opens a bag by its first bytes (ROS 1 "#ROSBAG V2.0", MCAP magic, SQLite header). A folder
/// (a ROS 2 bag folder with metadata.yaml) opens the single .db3 or .mcap file inside. Throws
/// Error naming the file when it is missing, not a bag, or broken before the first message.
std::unique_ptr<BagReader> open_bag(const std::string& path);

/// A ROS 1 bag or MCAP file already in memory (tests and fuzzers); `source` names it in errors.
std::unique_ptr<BagReader> open_bag_bytes(std::string bytes, const std::string& source);

/// True for the extensions of bags (.bag, .db3, .mcap) and for ROS 2 bag folders.
bool is_bag_path(const std::string& path);

}  // namespace scanmatch
