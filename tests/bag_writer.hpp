#pragma once
// Test-side writers for ROS bags, built from the format descriptions in scanmatch/io/bag/*.cpp:
// ROS 1 bags (chunks none/bz2/lz4), MCAP files (chunks none/zstd/lz4, or none) and ROS 2 .db3
// files, plus serializers (ROS 1 and CDR) for PointCloud2, Livox CustomMsg and LaserScan.

#include <bzlib.h>
#include <lz4frame.h>
#include <sqlite3.h>
#include <zlib.h>
#include <zstd.h>

#include <cstdint>
#include <cstring>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace scanmatch::test {

/// Serializes message fields: ROS 1 packed, or CDR little endian with its header and alignment.
class MsgWriter {
 public:
  explicit MsgWriter(bool cdr, bool big_endian = false) : cdr_(cdr), big_(big_endian) {
    if (cdr_) out_ = std::string("\0\x01\0\0", 4);
  }
  void align(std::size_t n) {
    if (cdr_)
      while ((out_.size() - 4) % n) out_ += '\0';
  }
  template <typename T>
  void put(T v) {
    align(sizeof(T));
    raw(&v, sizeof(T), big_);
  }
  void raw(const void* p, std::size_t n, bool swap = false) {
    std::string bytes(static_cast<const char*>(p), n);
    if (swap) bytes = std::string(bytes.rbegin(), bytes.rend());
    out_ += bytes;
  }
  void string(const std::string& s) {
    put<std::uint32_t>(static_cast<std::uint32_t>(s.size() + (cdr_ ? 1 : 0)));
    out_ += s;
    if (cdr_) out_ += '\0';
  }
  void header(std::int64_t stamp_ns, const std::string& frame = "lidar") {
    if (!cdr_) put<std::uint32_t>(7);  // seq
    put<std::uint32_t>(static_cast<std::uint32_t>(stamp_ns / 1000000000));
    put<std::uint32_t>(static_cast<std::uint32_t>(stamp_ns % 1000000000));
    string(frame);
  }
  bool cdr() const { return cdr_; }
  std::string& bytes() { return out_; }

 private:
  bool cdr_, big_;
  std::string out_;
};

/// A PointCloud2 field: name, PointField datatype (1..8) and byte offset in the point.
struct TestField {
  std::string name;
  std::uint8_t datatype;
  std::uint32_t offset;
};

inline std::size_t datatype_size(std::uint8_t t) {
  static const std::size_t sizes[] = {0, 1, 1, 2, 2, 4, 4, 4, 8};
  return sizes[t];
}

/// Writes one value of a PointField datatype, `big` for is_bigendian clouds.
inline void put_value(char* p, std::uint8_t t, double v, bool big) {
  char b[8];
  switch (t) {
    // clang-format off
    case 1: { auto x = static_cast<std::int8_t>(v); std::memcpy(b, &x, 1); break; }
    case 2: { auto x = static_cast<std::uint8_t>(v); std::memcpy(b, &x, 1); break; }
    case 3: { auto x = static_cast<std::int16_t>(v); std::memcpy(b, &x, 2); break; }
    case 4: { auto x = static_cast<std::uint16_t>(v); std::memcpy(b, &x, 2); break; }
    case 5: { auto x = static_cast<std::int32_t>(v); std::memcpy(b, &x, 4); break; }
    case 6: { auto x = static_cast<std::uint32_t>(v); std::memcpy(b, &x, 4); break; }
    case 7: { auto x = static_cast<float>(v); std::memcpy(b, &x, 4); break; }
    default: std::memcpy(b, &v, 8);
      // clang-format on
  }
  const std::size_t n = datatype_size(t);
  for (std::size_t i = 0; i < n; ++i) p[i] = big ? b[n - 1 - i] : b[i];
}

/// sensor_msgs/PointCloud2 of `values[point][field]` laid out in `height` rows of `width`, each
/// row padded by `row_padding` bytes.
inline std::string point_cloud2(bool cdr, std::int64_t stamp_ns,
                                const std::vector<TestField>& fields, std::uint32_t point_step,
                                const std::vector<std::vector<double>>& values,
                                std::uint32_t height = 1, std::uint32_t row_padding = 0,
                                bool big_endian = false) {
  MsgWriter w(cdr);
  w.header(stamp_ns);
  const auto width = static_cast<std::uint32_t>(values.size() / height);
  w.put<std::uint32_t>(height);
  w.put<std::uint32_t>(width);
  w.put<std::uint32_t>(static_cast<std::uint32_t>(fields.size()));
  for (const TestField& f : fields) {
    w.string(f.name);
    w.put<std::uint32_t>(f.offset);
    w.put<std::uint8_t>(f.datatype);
    w.put<std::uint32_t>(1);
  }
  w.put<std::uint8_t>(big_endian ? 1 : 0);
  const std::uint32_t row_step = width * point_step + row_padding;
  w.put<std::uint32_t>(point_step);
  w.put<std::uint32_t>(row_step);
  std::string data(std::size_t{row_step} * height, '\x55');
  for (std::size_t i = 0; i < values.size(); ++i)
    for (std::size_t k = 0; k < fields.size(); ++k)
      put_value(data.data() + (i / width) * row_step + (i % width) * point_step + fields[k].offset,
                fields[k].datatype, values[i][k], big_endian);
  w.put<std::uint32_t>(static_cast<std::uint32_t>(data.size()));
  w.bytes() += data;
  w.put<std::uint8_t>(1);  // is_dense
  return w.bytes();
}

struct TestLivoxPoint {
  std::uint32_t offset_time;
  float x, y, z;
  std::uint8_t reflectivity, tag, line;
};

inline std::string livox_custom(bool cdr, std::int64_t stamp_ns,
                                const std::vector<TestLivoxPoint>& points) {
  MsgWriter w(cdr);
  w.header(stamp_ns);
  w.put<std::uint64_t>(static_cast<std::uint64_t>(stamp_ns));
  w.put<std::uint32_t>(static_cast<std::uint32_t>(points.size()));
  w.put<std::uint8_t>(3);
  for (int i = 0; i < 3; ++i) w.put<std::uint8_t>(0);
  w.put<std::uint32_t>(static_cast<std::uint32_t>(points.size()));
  for (const TestLivoxPoint& p : points) {
    w.put(p.offset_time);
    w.put(p.x);
    w.put(p.y);
    w.put(p.z);
    w.put(p.reflectivity);
    w.put(p.tag);
    w.put(p.line);
  }
  return w.bytes();
}

inline std::string laser_scan(bool cdr, std::int64_t stamp_ns, float angle_min, float increment,
                              float range_max, const std::vector<float>& ranges,
                              const std::vector<float>& intensities) {
  MsgWriter w(cdr);
  w.header(stamp_ns, "laser");
  const float angle_max = angle_min + increment * static_cast<float>(ranges.size() - 1);
  for (float v : {angle_min, angle_max, increment, 0.0f, 0.1f, 0.0f, range_max}) w.put(v);
  w.put<std::uint32_t>(static_cast<std::uint32_t>(ranges.size()));
  for (float r : ranges) w.put(r);
  w.put<std::uint32_t>(static_cast<std::uint32_t>(intensities.size()));
  for (float r : intensities) w.put(r);
  return w.bytes();
}

struct TestMessage {
  std::string topic;
  std::int64_t time_ns;
  std::string data;
};

struct TestTopic {
  std::string name, type;
};

inline void put32(std::string& s, std::uint32_t v) {
  s.append(reinterpret_cast<char*>(&v), 4);
}
inline void put64(std::string& s, std::uint64_t v) {
  s.append(reinterpret_cast<char*>(&v), 8);
}

inline std::string compress_with(const std::string& codec, const std::string& in) {
  if (codec == "bz2") {
    std::string out(in.size() + in.size() / 100 + 700, '\0');
    auto n = static_cast<unsigned>(out.size());
    if (BZ2_bzBuffToBuffCompress(out.data(), &n, const_cast<char*>(in.data()),
                                 static_cast<unsigned>(in.size()), 9, 0, 0) != BZ_OK)
      throw std::runtime_error("bz2 compression failed");
    out.resize(n);
    return out;
  }
  if (codec == "lz4") {
    std::string out(LZ4F_compressFrameBound(in.size(), nullptr), '\0');
    const std::size_t n = LZ4F_compressFrame(out.data(), out.size(), in.data(), in.size(), nullptr);
    if (LZ4F_isError(n)) throw std::runtime_error("lz4 compression failed");
    out.resize(n);
    return out;
  }
  if (codec == "zstd") {
    std::string out(ZSTD_compressBound(in.size()), '\0');
    const std::size_t n = ZSTD_compress(out.data(), out.size(), in.data(), in.size(), 3);
    if (ZSTD_isError(n)) throw std::runtime_error("zstd compression failed");
    out.resize(n);
    return out;
  }
  return in;  // "none", "" and unknown names (for error tests) store the records as they are
}

/// ROS 1 bag record: header fields then data.
inline std::string ros1_record(const std::vector<std::pair<std::string, std::string>>& fields,
                               const std::string& data) {
  std::string header;
  for (const auto& [name, value] : fields) {
    put32(header, static_cast<std::uint32_t>(name.size() + 1 + value.size()));
    header += name + "=" + value;
  }
  std::string out;
  put32(out, static_cast<std::uint32_t>(header.size()));
  out += header;
  put32(out, static_cast<std::uint32_t>(data.size()));
  return out + data;
}

inline std::string bin32(std::uint32_t v) {
  return std::string(reinterpret_cast<char*>(&v), 4);
}
inline std::string bin64(std::uint64_t v) {
  return std::string(reinterpret_cast<char*>(&v), 8);
}
inline std::string ros_time(std::int64_t ns) {
  return bin32(static_cast<std::uint32_t>(ns / 1000000000)) +
         bin32(static_cast<std::uint32_t>(ns % 1000000000));
}

/// A ROS 1 bag: messages in file order, `per_chunk` to a chunk, then the index section
/// (connections and chunk infos). `index_pos` in the bag header points at it.
inline std::string ros1_bag(const std::vector<TestTopic>& topics,
                            const std::vector<TestMessage>& messages,
                            const std::string& compression = "none", std::size_t per_chunk = 3) {
  std::map<std::string, std::uint32_t> conn;
  for (const TestTopic& t : topics) conn.emplace(t.name, static_cast<std::uint32_t>(conn.size()));
  const auto connection_record = [&](const TestTopic& t) {
    const std::string data = ros1_record(
        {{"topic", t.name}, {"type", t.type}, {"md5sum", "*"}, {"message_definition", ""}}, "");
    // A connection's data is a bare field list: drop the record's two length words.
    return ros1_record({{"op", "\x07"}, {"conn", bin32(conn[t.name])}, {"topic", t.name}},
                       data.substr(4, data.size() - 8));
  };
  std::string body, chunk_infos;
  std::uint32_t chunk_count = 0;
  const std::string magic = "#ROSBAG V2.0\n";
  const std::size_t bag_header_size = 4096 + 4 + 4;  // fixed-size header record (padded)
  for (std::size_t start = 0; start < messages.size(); start += per_chunk) {
    std::string records;
    std::map<std::string, bool> seen;
    for (std::size_t i = start; i < std::min(messages.size(), start + per_chunk); ++i) {
      const TestMessage& m = messages[i];
      if (!seen[m.topic])
        for (const TestTopic& t : topics)
          if (t.name == m.topic) records += connection_record(t);
      seen[m.topic] = true;
      records += ros1_record(
          {{"op", "\x02"}, {"conn", bin32(conn[m.topic])}, {"time", ros_time(m.time_ns)}}, m.data);
    }
    const std::uint64_t chunk_pos = magic.size() + bag_header_size + body.size();
    body += ros1_record({{"op", "\x05"},
                         {"compression", compression},
                         {"size", bin32(static_cast<std::uint32_t>(records.size()))}},
                        compress_with(compression, records));
    chunk_infos += ros1_record({{"op", "\x06"},
                                {"ver", bin32(1)},
                                {"chunk_pos", bin64(chunk_pos)},
                                {"start_time", ros_time(0)},
                                {"end_time", ros_time(0)},
                                {"count", bin32(0)}},
                               "");
    ++chunk_count;
  }
  const std::uint64_t index_pos = magic.size() + bag_header_size + body.size();
  for (const TestTopic& t : topics) body += connection_record(t);
  body += chunk_infos;
  std::string header =
      ros1_record({{"op", "\x03"},
                   {"index_pos", bin64(index_pos)},
                   {"conn_count", bin32(static_cast<std::uint32_t>(topics.size()))},
                   {"chunk_count", bin32(chunk_count)}},
                  "");
  // Pad the data so the header record has its fixed size.
  const std::size_t header_len = header.size() - 8;
  header = header.substr(0, 4 + header_len);
  put32(header, static_cast<std::uint32_t>(4096 - header_len));
  header += std::string(4096 - header_len, ' ');
  return magic + header + body;
}

inline std::string mcap_string(const std::string& s) {
  return bin32(static_cast<std::uint32_t>(s.size())) + s;
}
inline std::string mcap_record(std::uint8_t op, const std::string& content) {
  return std::string(1, static_cast<char>(op)) + bin64(content.size()) + content;
}

/// An MCAP file: messages in file order, `per_chunk` to a chunk (0: no chunks). `ros1` writes
/// ROS 1 encoded channels ("ros1msg" schemas), otherwise "cdr" / "ros2msg".
inline std::string mcap_file(const std::vector<TestTopic>& topics,
                             const std::vector<TestMessage>& messages,
                             const std::string& compression = "", std::size_t per_chunk = 3,
                             bool ros1 = false) {
  std::string out = std::string("\x89MCAP0\r\n", 8);
  out += mcap_record(0x01, mcap_string(ros1 ? "ros1" : "ros2") + mcap_string("scanmatch test"));
  std::string defs;
  std::map<std::string, std::uint16_t> channel;
  for (const TestTopic& t : topics) {
    const auto id = static_cast<std::uint16_t>(channel.size() + 1);
    channel[t.name] = id;
    std::string schema(reinterpret_cast<const char*>(&id), 2);
    schema += mcap_string(t.type) + mcap_string(ros1 ? "ros1msg" : "ros2msg") + mcap_string("");
    defs += mcap_record(0x03, schema);
    std::string ch(reinterpret_cast<const char*>(&id), 2);
    ch += std::string(reinterpret_cast<const char*>(&id), 2);
    ch += mcap_string(t.name) + mcap_string(ros1 ? "ros1" : "cdr") + bin32(0);
    defs += mcap_record(0x04, ch);
  }
  const auto message_record = [&](const TestMessage& m, std::uint32_t seq) {
    const std::uint16_t id = channel[m.topic];
    std::string c(reinterpret_cast<const char*>(&id), 2);
    c += bin32(seq) + bin64(static_cast<std::uint64_t>(m.time_ns)) +
         bin64(static_cast<std::uint64_t>(m.time_ns));
    return mcap_record(0x05, c + m.data);
  };
  if (per_chunk == 0) {
    out += defs;
    for (std::size_t i = 0; i < messages.size(); ++i)
      out += message_record(messages[i], static_cast<std::uint32_t>(i));
  }
  for (std::size_t start = 0; per_chunk > 0 && start < messages.size(); start += per_chunk) {
    std::string records = start == 0 ? defs : "";
    for (std::size_t i = start; i < std::min(messages.size(), start + per_chunk); ++i)
      records += message_record(messages[i], static_cast<std::uint32_t>(i));
    const std::string compressed = compress_with(compression, records);
    const auto crc = static_cast<std::uint32_t>(crc32(
        0, reinterpret_cast<const Bytef*>(records.data()), static_cast<uInt>(records.size())));
    out += mcap_record(0x06, bin64(0) + bin64(0) + bin64(records.size()) + bin32(crc) +
                                 mcap_string(compression) + bin64(compressed.size()) + compressed);
  }
  out += mcap_record(0x0F, bin32(0));
  out += mcap_record(0x02, bin64(0) + bin64(0) + bin32(0));
  return out + std::string("\x89MCAP0\r\n", 8);
}

/// A ROS 2 SQLite bag at `path` (replaced if present).
inline void write_db3(const std::string& path, const std::vector<TestTopic>& topics,
                      const std::vector<TestMessage>& messages) {
  std::remove(path.c_str());
  sqlite3* db = nullptr;
  if (sqlite3_open(path.c_str(), &db) != SQLITE_OK) throw std::runtime_error("sqlite open");
  const auto exec = [&](const char* sql) {
    if (sqlite3_exec(db, sql, nullptr, nullptr, nullptr) != SQLITE_OK)
      throw std::runtime_error(sqlite3_errmsg(db));
  };
  exec("PRAGMA synchronous=OFF");
  exec("BEGIN");
  exec(
      "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, "
      "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL)");
  exec(
      "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, "
      "timestamp INTEGER NOT NULL, data BLOB NOT NULL)");
  std::map<std::string, int> id;
  sqlite3_stmt* st = nullptr;
  sqlite3_prepare_v2(db, "INSERT INTO topics VALUES(?, ?, ?, 'cdr', '')", -1, &st, nullptr);
  for (const TestTopic& t : topics) {
    id[t.name] = static_cast<int>(id.size()) + 1;
    sqlite3_bind_int(st, 1, id[t.name]);
    sqlite3_bind_text(st, 2, t.name.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(st, 3, t.type.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_step(st);
    sqlite3_reset(st);
  }
  sqlite3_finalize(st);
  sqlite3_prepare_v2(db, "INSERT INTO messages(topic_id, timestamp, data) VALUES(?, ?, ?)", -1, &st,
                     nullptr);
  for (const TestMessage& m : messages) {
    sqlite3_bind_int(st, 1, id[m.topic]);
    sqlite3_bind_int64(st, 2, m.time_ns);
    sqlite3_bind_blob(st, 3, m.data.data(), static_cast<int>(m.data.size()), SQLITE_TRANSIENT);
    sqlite3_step(st);
    sqlite3_reset(st);
  }
  sqlite3_finalize(st);
  exec("COMMIT");
  sqlite3_close(db);
}

}  // namespace scanmatch::test
