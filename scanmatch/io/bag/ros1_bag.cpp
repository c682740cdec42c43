// ROS 1 bag format 2.0: after the "#ROSBAG V2.0\n" line, records of
//   u32 header_len, header (fields: u32 len, "name=value"), u32 data_len, data.
// The header's one-byte "op" field gives the kind: 0x03 bag header, 0x05 chunk (fields
// "compression" none/bz2/lz4 and "size", the uncompressed size; data: more records), 0x07
// connection (header "conn", "topic"; data: fields "type", "md5sum", "message_definition", ...),
// 0x02 message data (header "conn" and "time" = u32 sec, u32 nsec; data: the serialized message),
// 0x04 index data and 0x06 chunk info (not needed: chunks are read in file order).

#include <map>
#include <optional>

#include "scanmatch/io/bag/bag_detail.hpp"

namespace scanmatch::bag_detail {
namespace {

constexpr std::string_view kRosbagMagic = "#ROSBAG V2.0\n";
constexpr std::uint8_t kOpMessage = 0x02, kOpBagHeader = 0x03, kOpChunk = 0x05,
                       kOpConnection = 0x07;

/// The "name=value" fields of a record header (or of a connection record's data).
class HeaderFields {
 public:
  explicit HeaderFields(Cursor& c) : cursor_(c) {
    while (!c.at_end()) {
      const std::uint64_t at = c.offset();
      const std::string_view field = c.prefixed32("header field");
      const std::size_t eq = field.find('=');
      if (eq == std::string_view::npos) c.fail_at(at, "header field has no '='");
      fields_.push_back({field.substr(0, eq), field.substr(eq + 1), at});
    }
  }
  std::optional<std::string_view> find(std::string_view name) const {
    for (const Field& f : fields_)
      if (f.name == name) return f.value;
    return std::nullopt;
  }
  std::string_view get(std::string_view name, std::size_t size = 0) const {
    for (const Field& f : fields_) {
      if (f.name != name) continue;
      if (size != 0 && f.value.size() != size)
        cursor_.fail_at(f.offset, "header field '" + std::string(name) + "' has " +
                                      std::to_string(f.value.size()) + " bytes, expected " +
                                      std::to_string(size));
      return f.value;
    }
    cursor_.fail_at(cursor_.offset(), "record header has no '" + std::string(name) + "' field");
  }
  template <typename T>
  T number(std::string_view name) const {
    T value;
    std::memcpy(&value, get(name, sizeof(T)).data(), sizeof(T));
    return value;
  }

 private:
  struct Field {
    std::string_view name, value;
    std::uint64_t offset;
  };
  Cursor& cursor_;
  std::vector<Field> fields_;
};

class Ros1Bag : public IndexedBag {
 public:
  explicit Ros1Bag(ByteSource source) : IndexedBag(std::move(source)) {}
  std::string format() const override { return "ROS 1 bag"; }

  void index() {
    const std::string head =
        source_.read(0, std::min<std::uint64_t>(source_.size(), kRosbagMagic.size()), "header");
    if (head != kRosbagMagic) {
      const std::string version = head.substr(0, head.find('\n'));
      fail(source_.name(), "unsupported bag version '" + version + "' (only #ROSBAG V2.0)");
    }
    std::uint64_t offset = kRosbagMagic.size();
    try {
      while (offset < source_.size()) offset = top_level_record(offset);
      if (!has_header_)
        fail(source_.name(), "byte " + std::to_string(kRosbagMagic.size()), "no bag header record");
      // A closed bag points at its index section; a file ending before it was cut short.
      if (index_pos_ > source_.size())
        fail(source_.name(), "byte " + std::to_string(source_.size()),
             "truncated: the file ends before its index at byte " + std::to_string(index_pos_));
    } catch (const Error& e) {
      record_fault(e);
    }
    // Messages whose connection record never came are dropped, and the bag is reported faulty.
    std::vector<MessageRef> kept;
    for (MessageRef m : messages_) {
      const auto it = slot_of_conn_.find(m.topic);
      if (it == slot_of_conn_.end()) {
        if (!fault_)
          fault_ = source_.name() + ": message on connection " + std::to_string(m.topic) +
                   " that the bag never defines";
        continue;
      }
      m.topic = it->second;
      kept.push_back(m);
    }
    messages_ = std::move(kept);
    if (messages_.empty() && fault_) throw Error(*fault_);
    finish_index(slots_);
  }

 private:
  /// Reads the record at `offset`; returns the offset after it.
  std::uint64_t top_level_record(std::uint64_t offset) {
    std::uint32_t header_len, data_len;
    std::memcpy(&header_len, source_.read(offset, 4, "record header length").data(), 4);
    const std::string header = source_.read(offset + 4, header_len, "record header");
    const std::uint64_t data_len_at = offset + 4 + header_len;
    std::memcpy(&data_len, source_.read(data_len_at, 4, "record data length").data(), 4);
    const std::uint64_t data_at = data_len_at + 4;
    if (data_len > source_.size() - data_at)
      fail(source_.name(), "byte " + std::to_string(data_len_at),
           "truncated record: data of " + std::to_string(data_len) + " bytes, " +
               std::to_string(source_.size() - data_at) + " remain");
    Cursor hc(header, source_.name(), "", offset + 4);
    const HeaderFields fields(hc);
    const std::uint8_t op = fields.number<std::uint8_t>("op");
    if (op == kOpBagHeader) {
      index_pos_ = fields.number<std::uint64_t>("index_pos");
      has_header_ = true;
    } else if (op == kOpChunk) {
      chunk(fields, offset, data_at, data_len);
    } else if (op == kOpConnection) {
      const std::string data = source_.read(data_at, data_len, "connection");
      Cursor dc(data, source_.name(), "", data_at);
      connection(fields, dc);
    } else if (op == kOpMessage) {
      message(fields, data_at, data_len, -1);
    }
    return data_at + data_len;
  }

  void chunk(const HeaderFields& fields, std::uint64_t offset, std::uint64_t data_at,
             std::uint32_t data_len) {
    ChunkRef c;
    c.file_offset = offset;
    c.data_offset = data_at;
    c.data_size = data_len;
    c.compression = std::string(fields.get("compression"));
    c.uncompressed_size = fields.number<std::uint32_t>("size");
    const std::string context = "chunk at byte " + std::to_string(offset);
    const std::string records = decompress(c.compression, source_.read(data_at, data_len, "chunk"),
                                           c.uncompressed_size, source_.name(), context);
    const auto chunk_index = static_cast<std::int32_t>(chunks_.size());
    chunks_.push_back(std::move(c));
    Cursor cursor(records, source_.name(), context, 0);
    while (!cursor.at_end()) {
      const std::uint64_t header_offset = cursor.offset() + 4;
      const std::string_view header = cursor.prefixed32("record header");
      Cursor hc(header, source_.name(), context, header_offset);
      const HeaderFields inner(hc);
      const std::uint64_t data_offset = cursor.offset() + 4;
      const std::string_view data = cursor.prefixed32("record data");
      Cursor dc(data, source_.name(), context, data_offset);
      const std::uint8_t op = inner.number<std::uint8_t>("op");
      if (op == kOpConnection)
        connection(inner, dc);
      else if (op == kOpMessage)
        message(inner, data_offset, dc.remaining(), chunk_index);
    }
  }

  void connection(const HeaderFields& fields, Cursor& data) {
    const std::uint32_t conn = fields.number<std::uint32_t>("conn");
    const std::string topic(fields.get("topic"));
    const HeaderFields info(data);
    if (slot_of_conn_.count(conn)) return;  // connections are repeated after the chunks
    BagTopic t;
    t.name = topic;
    t.type = std::string(info.find("type").value_or(""));
    t.encoding = "ros1";
    slot_of_conn_[conn] = static_cast<std::uint32_t>(slots_.size());
    slots_.push_back(std::move(t));
  }

  void message(const HeaderFields& fields, std::uint64_t data_offset, std::uint64_t size,
               std::int32_t chunk) {
    MessageRef m;
    m.topic = fields.number<std::uint32_t>("conn");  // resolved to a slot in index()
    const std::uint64_t time = fields.number<std::uint64_t>("time");
    m.time_ns = static_cast<std::int64_t>(time & 0xffffffffu) * 1000000000 +
                static_cast<std::int64_t>(time >> 32);
    m.offset = data_offset;
    m.size = static_cast<std::uint32_t>(size);
    m.chunk = chunk;
    messages_.push_back(m);
  }

  std::uint64_t index_pos_ = 0;
  bool has_header_ = false;
  std::map<std::uint32_t, std::uint32_t> slot_of_conn_;
  std::vector<BagTopic> slots_;
};

}  // namespace

std::unique_ptr<BagReader> open_ros1_bag(ByteSource source) {
  auto bag = std::make_unique<Ros1Bag>(std::move(source));
  bag->index();
  return bag;
}

}  // namespace scanmatch::bag_detail
