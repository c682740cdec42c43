#pragma once
// Internal parts shared by the bag readers: bounds-checked byte access to a file or memory,
// chunk decompression, and the message index that ROS 1 bags and MCAP files are walked through.
// Not part of the public API.

#include <cstdint>
#include <cstring>
#include <fstream>
#include <list>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "scanmatch/core/error.hpp"
#include "scanmatch/io/bag/bag.hpp"

namespace scanmatch::bag_detail {

/// An MCAP file's first (and last) 8 bytes.
inline constexpr std::string_view kMcapMagic = "\x89MCAP0\r\n";

/// Largest decompressed chunk accepted (a real chunk is a few MiB).
inline constexpr std::uint64_t kMaxChunkBytes = std::uint64_t{1} << 30;

/// Random access to the bytes of a file (read on demand, so bags larger than memory work) or of
/// a buffer. Every read is checked against the size first.
class ByteSource {
 public:
  static ByteSource open_file(const std::string& path);
  static ByteSource from_memory(std::string bytes, std::string name);
  const std::string& name() const { return name_; }
  std::uint64_t size() const { return size_; }
  /// `n` bytes at `offset`; Error "truncated" naming `what` when the source ends first.
  std::string read(std::uint64_t offset, std::uint64_t n, const char* what);

 private:
  std::string name_;
  std::uint64_t size_ = 0;
  std::shared_ptr<std::ifstream> file_;
  std::string memory_;
  bool in_memory_ = false;
};

/// Little-endian reads from a buffer; every read checks the remaining bytes and an error names
/// the file, the buffer's place (`context`, e.g. "chunk at byte 4096") and the offset.
class Cursor {
 public:
  Cursor(std::string_view data, const std::string& source, std::string context, std::uint64_t base)
      : data_(data), source_(source), context_(std::move(context)), base_(base) {}
  std::size_t pos() const { return pos_; }
  std::size_t remaining() const { return data_.size() - pos_; }
  bool at_end() const { return pos_ == data_.size(); }
  std::uint64_t offset() const { return base_ + pos_; }  ///< of the next byte, in the context
  std::string where(std::uint64_t at) const {
    return (context_.empty() ? "" : context_ + ", ") + "byte " + std::to_string(at);
  }
  [[noreturn]] void fail_at(std::uint64_t at, const std::string& problem) const {
    fail(source_, where(at), problem);
  }
  std::string_view take(std::uint64_t n, const char* what) {
    if (n > remaining())
      fail_at(offset(), std::string("truncated ") + what + ": needs " + std::to_string(n) +
                            " bytes, " + std::to_string(remaining()) + " remain");
    const std::string_view out = data_.substr(pos_, n);
    pos_ += n;
    return out;
  }
  template <typename T>
  T read(const char* what) {
    T value;
    std::memcpy(&value, take(sizeof(T), what).data(), sizeof(T));
    return value;
  }
  /// A u32-length-prefixed byte string (MCAP strings, ROS 1 header fields).
  std::string_view prefixed32(const char* what) { return take(read<std::uint32_t>(what), what); }

 private:
  std::string_view data_;
  const std::string& source_;
  std::string context_;
  std::uint64_t base_;
  std::size_t pos_ = 0;
};

/// Decompresses a chunk ("none" or "" copy; "bz2", "lz4" frame, "zstd") that must come out at
/// exactly `size` bytes. Error naming `where` for unknown compression, corrupt, truncated or
/// wrongly sized data.
std::string decompress(std::string_view compression, std::string_view data, std::uint64_t size,
                       const std::string& source, const std::string& where);

/// Where a message's bytes are: a range of the file, or of a chunk's decompressed records.
struct MessageRef {
  std::int64_t time_ns = 0;
  std::uint64_t offset = 0;  ///< in the file (chunk < 0) or in the decompressed chunk
  std::uint32_t size = 0;
  std::int32_t chunk = -1;
  std::uint32_t topic = 0;  ///< index in topics() (after finish_index)
};

struct ChunkRef {
  std::uint64_t file_offset = 0;  ///< of the chunk record, for messages
  std::uint64_t data_offset = 0, data_size = 0, uncompressed_size = 0;
  std::string compression;
  std::uint32_t crc = 0;  ///< of the uncompressed data; 0: not checked
};

/// ROS 1 bags and MCAP files: opening indexes every message (reading the file once, chunk by
/// chunk); next() then walks the selected topics in time order, decompressing each chunk again
/// when first needed (a few stay cached, so chunks that overlap in time stay cheap).
class IndexedBag : public BagReader {
 public:
  void select(const std::vector<std::string>& topics) override;
  bool next(BagMessage& message) override;

 protected:
  explicit IndexedBag(ByteSource source) : source_(std::move(source)) { path_ = source_.name(); }
  /// Sorts topics by name and maps `messages` (whose `topic` holds a connection slot) to them.
  /// `slot_topic[i]` is the topic name of slot i with its type and encoding.
  void finish_index(const std::vector<BagTopic>& slot_topic);
  /// Records a fault: throws when no message was indexed yet (nothing to deliver).
  void record_fault(const Error& error);
  const std::string& chunk_bytes(std::size_t chunk);

  ByteSource source_;
  std::vector<MessageRef> messages_;
  std::vector<ChunkRef> chunks_;

 private:
  std::vector<std::uint32_t> order_;
  std::size_t next_ = 0;
  std::list<std::pair<std::size_t, std::string>> cache_;  // most recent first
};

std::unique_ptr<BagReader> open_ros1_bag(ByteSource source);
std::unique_ptr<BagReader> open_mcap(ByteSource source);
std::unique_ptr<BagReader> open_db3(const std::string& path);

}  // namespace scanmatch::bag_detail
