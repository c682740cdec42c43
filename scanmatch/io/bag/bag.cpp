#include "scanmatch/io/bag/bag.hpp"

#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <filesystem>
#include <map>

#include "scanmatch/io/bag/bag_detail.hpp"
#include "scanmatch/io/file_util.hpp"

namespace scanmatch {
namespace bag_detail {

ByteSource ByteSource::open_file(const std::string& path) {
  ByteSource s;
  s.name_ = path;
  s.file_ = std::make_shared<std::ifstream>(path, std::ios::binary);
  if (!*s.file_) fail(path, std::string("cannot open: ") + std::strerror(errno));
  s.file_->seekg(0, std::ios::end);
  const std::streamoff size = s.file_->tellg();
  if (size < 0) fail(path, "cannot determine the file size");
  s.size_ = static_cast<std::uint64_t>(size);
  return s;
}

ByteSource ByteSource::from_memory(std::string bytes, std::string name) {
  ByteSource s;
  s.name_ = std::move(name);
  s.memory_ = std::move(bytes);
  s.size_ = s.memory_.size();
  s.in_memory_ = true;
  return s;
}

std::string ByteSource::read(std::uint64_t offset, std::uint64_t n, const char* what) {
  if (offset > size_ || n > size_ - offset)
    fail(name_, "byte " + std::to_string(offset),
         std::string("truncated ") + what + ": needs " + std::to_string(n) + " bytes, " +
             std::to_string(offset > size_ ? 0 : size_ - offset) + " remain");
  if (in_memory_) return memory_.substr(offset, n);
  std::string out(n, '\0');
  file_->clear();
  file_->seekg(static_cast<std::streamoff>(offset));
  if (!file_->read(out.data(), static_cast<std::streamsize>(n)))
    fail(name_, "byte " + std::to_string(offset), "read error");
  return out;
}

void IndexedBag::finish_index(const std::vector<BagTopic>& slot_topic) {
  std::map<std::string, std::uint32_t> by_name;
  for (const BagTopic& t : slot_topic) by_name.emplace(t.name, 0);
  std::uint32_t index = 0;
  for (auto& [name, i] : by_name) i = index++;
  topics_.assign(by_name.size(), {});
  for (const BagTopic& t : slot_topic) {
    BagTopic& topic = topics_[by_name[t.name]];
    if (topic.name.empty()) topic = {t.name, t.type, t.encoding, 0};
  }
  for (MessageRef& m : messages_) {
    m.topic = by_name[slot_topic[m.topic].name];
    ++topics_[m.topic].message_count;
  }
  select({});
}

void IndexedBag::record_fault(const Error& error) {
  if (messages_.empty()) throw error;
  fault_ = error.what();
}

void IndexedBag::select(const std::vector<std::string>& topics) {
  check_topics(topics);
  std::vector<bool> wanted(topics_.size(), topics.empty());
  for (const std::string& name : topics)
    wanted[static_cast<std::size_t>(find_topic(name) - topics_.data())] = true;
  order_.clear();
  for (std::size_t i = 0; i < messages_.size(); ++i)
    if (wanted[messages_[i].topic]) order_.push_back(static_cast<std::uint32_t>(i));
  std::stable_sort(order_.begin(), order_.end(), [this](std::uint32_t a, std::uint32_t b) {
    return messages_[a].time_ns < messages_[b].time_ns;
  });
  next_ = 0;
}

const std::string& IndexedBag::chunk_bytes(std::size_t chunk) {
  for (auto it = cache_.begin(); it != cache_.end(); ++it)
    if (it->first == chunk) {
      cache_.splice(cache_.begin(), cache_, it);
      return cache_.front().second;
    }
  const ChunkRef& c = chunks_[chunk];
  const std::string where = "chunk at byte " + std::to_string(c.file_offset);
  std::string data = decompress(c.compression, source_.read(c.data_offset, c.data_size, "chunk"),
                                c.uncompressed_size, source_.name(), where);
  if (c.crc != 0 && crc32(0, reinterpret_cast<const Bytef*>(data.data()),
                          static_cast<uInt>(data.size())) != c.crc)
    fail(source_.name(), where, "CRC of the decompressed records does not match");
  cache_.emplace_front(chunk, std::move(data));
  if (cache_.size() > 4) cache_.pop_back();
  return cache_.front().second;
}

bool IndexedBag::next(BagMessage& message) {
  if (next_ >= order_.size()) {
    if (fault_) throw Error(*fault_);
    return false;
  }
  const MessageRef& m = messages_[order_[next_++]];
  const BagTopic& topic = topics_[m.topic];
  message.timestamp_ns = m.time_ns;
  message.topic = topic.name;
  message.type = topic.type;
  message.encoding = topic.encoding;
  if (m.chunk < 0) {
    message.data = source_.read(m.offset, m.size, "message");
    message.where = "byte " + std::to_string(m.offset);
  } else {
    // The index pass checked the range against the chunk's declared size.
    message.data = chunk_bytes(static_cast<std::size_t>(m.chunk)).substr(m.offset, m.size);
    message.where = "chunk at byte " + std::to_string(chunks_[m.chunk].file_offset) + ", byte " +
                    std::to_string(m.offset);
  }
  return true;
}

}  // namespace bag_detail

const BagTopic* BagReader::find_topic(const std::string& name) const {
  for (const BagTopic& t : topics_)
    if (t.name == name) return &t;
  return nullptr;
}

void BagReader::check_topics(const std::vector<std::string>& names) const {
  for (const std::string& name : names) {
    if (find_topic(name)) continue;
    std::string list;
    for (const BagTopic& t : topics_) list += (list.empty() ? "" : ", ") + t.name;
    fail(path_, "topic " + name, "not in the bag (topics: " + (list.empty() ? "none" : list) + ")");
  }
}

namespace {

constexpr std::string_view kRos1Magic = "#ROSBAG V";
constexpr std::string_view kSqliteMagic{"SQLite format 3\0", 16};

std::string bag_in_folder(const std::string& path) {
  std::vector<std::string> found;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(path, ec)) {
    const std::string ext = extension_without_gz(entry.path().string());
    if (entry.is_regular_file() && (ext == "db3" || ext == "mcap" || ext == "bag"))
      found.push_back(entry.path().string());
  }
  if (ec) fail(path, "cannot list the folder: " + ec.message());
  std::sort(found.begin(), found.end());
  if (found.size() == 1) return found.front();
  if (found.empty()) fail(path, "holds no .db3, .mcap or .bag file");
  fail(path, "holds " + std::to_string(found.size()) +
                 " bag files (split bags are not supported): open one of them");
}

std::unique_ptr<BagReader> open_by_magic(bag_detail::ByteSource source) {
  const std::string head = source.read(0, std::min<std::uint64_t>(source.size(), 16), "header");
  const std::string_view h = head;
  if (h.substr(0, kRos1Magic.size()) == kRos1Magic)
    return bag_detail::open_ros1_bag(std::move(source));
  if (h.substr(0, bag_detail::kMcapMagic.size()) == bag_detail::kMcapMagic)
    return bag_detail::open_mcap(std::move(source));
  if (source.size() == 0) fail(source.name(), "file is empty");
  fail(source.name(), "not a ROS 1 bag, ROS 2 .db3 or MCAP file (unknown first bytes)");
}

}  // namespace

std::unique_ptr<BagReader> open_bag(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) fail(path, "does not exist");
  if (std::filesystem::is_directory(path, ec)) return open_bag(bag_in_folder(path));
  bag_detail::ByteSource source = bag_detail::ByteSource::open_file(path);
  if (source.size() >= kSqliteMagic.size() &&
      source.read(0, kSqliteMagic.size(), "header") == kSqliteMagic)
    return bag_detail::open_db3(path);
  return open_by_magic(std::move(source));
}

std::unique_ptr<BagReader> open_bag_bytes(std::string bytes, const std::string& source) {
  return open_by_magic(bag_detail::ByteSource::from_memory(std::move(bytes), source));
}

bool is_bag_path(const std::string& path) {
  const std::string ext = extension_without_gz(path);
  if (ext == "bag" || ext == "db3" || ext == "mcap") return true;
  std::error_code ec;
  return std::filesystem::is_regular_file(std::filesystem::path(path) / "metadata.yaml", ec);
}

}  // namespace scanmatch
