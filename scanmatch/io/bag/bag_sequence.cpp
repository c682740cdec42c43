#include "scanmatch/io/bag/bag_sequence.hpp"

#include "scanmatch/core/error.hpp"

namespace scanmatch {
namespace {

bool is_scan_type(std::string_view type) {
  return ros_message_type(type) == RosMessageType::kLaserScan;
}

class BagSequence : public SequenceSource {
 public:
  BagSequence(std::unique_ptr<BagReader> bag, std::string topic)
      : bag_(std::move(bag)), topic_(std::move(topic)) {
    bag_->select({topic_});
    size_ = static_cast<std::size_t>(bag_->find_topic(topic_)->message_count);
    // A fault counts as one more frame, so that a reader asking for size() frames meets it.
    if (bag_->fault()) ++size_;
  }

  std::size_t size() const override { return size_; }

  bool next(Frame& frame) override {
    BagMessage message;
    if (!bag_->next(message)) return false;
    std::int64_t stamp = 0;
    frame.cloud = decode_cloud_message(message, bag_->path(), &stamp);
    frame.index = index_++;
    frame.timestamp = static_cast<double>(stamp) * 1e-9;
    frame.name = bag_->path() + ":" + topic_ + "#" + std::to_string(frame.index);
    return true;
  }

  std::string describe() const override {
    return bag_->format() + " " + bag_->path() + " topic " + topic_ + " (" + std::to_string(size_) +
           " frames)";
  }

 private:
  std::unique_ptr<BagReader> bag_;
  std::string topic_;
  std::size_t size_ = 0, index_ = 0;
};

}  // namespace

std::string choose_bag_topic(const BagReader& bag, const std::string& topic,
                             bool (*accept)(std::string_view type), const std::string& what) {
  std::vector<std::string> candidates;
  std::string all;
  for (const BagTopic& t : bag.topics()) {
    if (accept(t.type)) candidates.push_back(t.name);
    all += (all.empty() ? "" : ", ") + t.name + " (" + t.type + ")";
  }
  if (!topic.empty()) {
    const BagTopic* t = bag.find_topic(topic);
    if (!t) fail(bag.path(), "topic " + topic, "not in the bag (topics: " + all + ")");
    if (!accept(t->type))
      fail(bag.path(), "topic " + topic, "type " + t->type + " is not a " + what + " type");
    return topic;
  }
  if (candidates.size() == 1) return candidates.front();
  if (candidates.empty())
    fail(bag.path(), "no " + what + " topic (topics: " + (all.empty() ? "none" : all) + ")");
  std::string list;
  for (const std::string& c : candidates) list += (list.empty() ? "" : ", ") + c;
  fail(bag.path(), std::to_string(candidates.size()) + " " + what +
                       " topics, choose one with --topic: " + list);
}

std::unique_ptr<SequenceSource> open_bag_sequence(const std::string& path,
                                                  const std::string& topic) {
  auto bag = open_bag(path);
  const std::string chosen = choose_bag_topic(*bag, topic, &is_cloud_type, "point cloud");
  return std::make_unique<BagSequence>(std::move(bag), chosen);
}

std::vector<LaserScan2D> read_bag_laser_scans(const std::string& path, const std::string& topic,
                                              std::size_t max_scans) {
  const auto bag = open_bag(path);
  bag->select({choose_bag_topic(*bag, topic, &is_scan_type, "laser scan")});
  std::vector<LaserScan2D> scans;
  BagMessage message;
  while ((max_scans == 0 || scans.size() < max_scans) && bag->next(message))
    scans.push_back(decode_laser_scan(message, path));
  return scans;
}

}  // namespace scanmatch
