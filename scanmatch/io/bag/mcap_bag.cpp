// MCAP: the magic "\x89MCAP0\r\n", then records of u8 opcode, u64 length, content; integers
// little endian, strings as u32 length + bytes. Read here: Schema (0x03: u16 id, name, encoding,
// u32-prefixed data), Channel (0x04: u16 id, u16 schema id, topic, message encoding, metadata
// map), Message (0x05: u16 channel, u32 sequence, u64 log time, u64 publish time, data) and Chunk
// (0x06: u64 start, u64 end, u64 uncompressed size, u32 uncompressed CRC-32 (0: none),
// compression "", "lz4" or "zstd", u64-prefixed records). Reading stops at Data End (0x0F) or
// the Footer (0x02); the summary section only repeats what the data section holds.

#include <map>

#include "scanmatch/io/bag/bag_detail.hpp"

namespace scanmatch::bag_detail {
namespace {

constexpr std::uint8_t kFooter = 0x02, kSchema = 0x03, kChannel = 0x04, kMessage = 0x05,
                       kChunk = 0x06, kDataEnd = 0x0F;
constexpr std::uint64_t kMessagePrefix = 2 + 4 + 8 + 8;

class McapBag : public IndexedBag {
 public:
  explicit McapBag(ByteSource source) : IndexedBag(std::move(source)) {}
  std::string format() const override { return "MCAP"; }

  void index() {
    if (source_.read(0, std::min<std::uint64_t>(source_.size(), 8), "magic") != kMcapMagic)
      fail(source_.name(), "not an MCAP file (bad magic)");
    std::uint64_t offset = kMcapMagic.size();
    try {
      bool done = false;
      while (!done) {
        if (offset == source_.size())
          fail(source_.name(), "byte " + std::to_string(offset),
               "file ends without Data End or Footer record (truncated)");
        done = top_level_record(offset);
      }
    } catch (const Error& e) {
      record_fault(e);
    }
    std::vector<BagTopic> slots;
    std::map<std::uint16_t, std::uint32_t> slot_of_channel;
    for (const auto& [id, channel] : channels_) {
      slot_of_channel[id] = static_cast<std::uint32_t>(slots.size());
      BagTopic t;
      t.name = channel.topic;
      const auto schema = schemas_.find(channel.schema);
      if (schema != schemas_.end()) t.type = schema->second;
      t.encoding = channel.encoding;
      slots.push_back(std::move(t));
    }
    std::vector<MessageRef> kept;
    for (MessageRef m : messages_) {
      const auto it = slot_of_channel.find(static_cast<std::uint16_t>(m.topic));
      if (it == slot_of_channel.end()) {
        if (!fault_)
          fault_ = source_.name() + ": message on channel " + std::to_string(m.topic) +
                   " that the file never defines";
        continue;
      }
      m.topic = it->second;
      kept.push_back(m);
    }
    messages_ = std::move(kept);
    if (messages_.empty() && fault_) throw Error(*fault_);
    finish_index(slots);
  }

 private:
  struct Channel {
    std::uint16_t schema = 0;
    std::string topic, encoding;
  };

  /// Reads the record at `offset`, advancing it; true at the end of the data section.
  bool top_level_record(std::uint64_t& offset) {
    const std::string head = source_.read(offset, 9, "record opcode and length");
    const auto op = static_cast<std::uint8_t>(head[0]);
    std::uint64_t length;
    std::memcpy(&length, head.data() + 1, 8);
    const std::uint64_t content_at = offset + 9;
    if (length > source_.size() - content_at)
      fail(source_.name(), "byte " + std::to_string(offset),
           "truncated record: " + std::to_string(length) + " bytes of content, " +
               std::to_string(source_.size() - content_at) + " remain");
    const std::uint64_t record_at = offset;
    offset = content_at + length;
    if (op == kFooter || op == kDataEnd) return true;
    if (op != kSchema && op != kChannel && op != kMessage && op != kChunk) return false;
    // A message's data is read when delivered, not now.
    const std::uint64_t read = op == kMessage ? std::min(length, kMessagePrefix) : length;
    const std::string content = source_.read(content_at, read, "record");
    Cursor c(content, source_.name(), "", content_at);
    if (op == kChunk)
      chunk(c, record_at);
    else
      record(op, c, length, -1);
    return false;
  }

  /// Schema, Channel or Message content; `length` is the full content length.
  void record(std::uint8_t op, Cursor& c, std::uint64_t length, std::int32_t chunk) {
    if (op == kSchema) {
      const auto id = c.read<std::uint16_t>("schema id");
      const std::string name(c.prefixed32("schema name"));
      c.prefixed32("schema encoding");
      c.prefixed32("schema data");
      if (id != 0) schemas_.emplace(id, name);
    } else if (op == kChannel) {
      const auto id = c.read<std::uint16_t>("channel id");
      Channel channel;
      channel.schema = c.read<std::uint16_t>("channel schema id");
      channel.topic = std::string(c.prefixed32("channel topic"));
      channel.encoding = std::string(c.prefixed32("channel message encoding"));
      c.prefixed32("channel metadata");
      channels_.emplace(id, std::move(channel));
    } else if (op == kMessage) {
      const std::uint64_t start = c.offset();
      if (length < kMessagePrefix) c.fail_at(start, "message record is shorter than its fields");
      MessageRef m;
      m.topic = c.read<std::uint16_t>("message channel id");
      c.read<std::uint32_t>("message sequence");
      const auto log_time = c.read<std::uint64_t>("message log time");
      c.read<std::uint64_t>("message publish time");
      if (length - kMessagePrefix > 0xffffffffu) c.fail_at(start, "message larger than 4 GiB");
      m.time_ns = static_cast<std::int64_t>(log_time);
      m.offset = start + kMessagePrefix;
      m.size = static_cast<std::uint32_t>(length - kMessagePrefix);
      m.chunk = chunk;
      messages_.push_back(m);
    }
  }

  void chunk(Cursor& c, std::uint64_t record_at) {
    ChunkRef ref;
    ref.file_offset = record_at;
    c.read<std::uint64_t>("chunk start time");
    c.read<std::uint64_t>("chunk end time");
    ref.uncompressed_size = c.read<std::uint64_t>("chunk uncompressed size");
    ref.crc = c.read<std::uint32_t>("chunk CRC");
    ref.compression = std::string(c.prefixed32("chunk compression"));
    const auto records_size = c.read<std::uint64_t>("chunk records length");
    ref.data_offset = c.offset();
    c.take(records_size, "chunk records");
    ref.data_size = records_size;
    const std::string context = "chunk at byte " + std::to_string(record_at);
    chunks_.push_back(ref);
    // The CRC is checked by chunk_bytes (the same code that delivers the messages later).
    const std::string& records = chunk_bytes(chunks_.size() - 1);
    const auto chunk_index = static_cast<std::int32_t>(chunks_.size() - 1);
    Cursor r(records, source_.name(), context, 0);
    while (!r.at_end()) {
      const auto op = r.read<std::uint8_t>("record opcode");
      const auto length = r.read<std::uint64_t>("record length");
      const std::uint64_t at = r.offset();
      const std::string_view content = r.take(length, "record");
      Cursor inner(content, source_.name(), context, at);
      record(op, inner, length, chunk_index);
    }
  }

  std::map<std::uint16_t, std::string> schemas_;
  std::map<std::uint16_t, Channel> channels_;
};

}  // namespace

std::unique_ptr<BagReader> open_mcap(ByteSource source) {
  auto bag = std::make_unique<McapBag>(std::move(source));
  bag->index();
  return bag;
}

}  // namespace scanmatch::bag_detail
