#include "scanmatch/io/pcd.hpp"

#include <cstdio>
#include <cstring>

#include "scanmatch/io/lzf.hpp"
#include "scanmatch/io/parse_util.hpp"

namespace scanmatch {
namespace {
using namespace io_detail;

struct PcdField {
  std::string name;
  ScalarType type;
  std::size_t count = 1;
  std::size_t offset = 0;  // byte offset within a point record
  FieldRole role = FieldRole::kIgnore;
};

struct PcdHeader {
  std::vector<PcdField> fields;
  std::uint64_t width = 0, height = 1, points = 0;
  bool has_points = false, has_width = false;
  std::string data;
  std::size_t point_bytes = 0;
  std::size_t data_offset = 0;  // first byte after the DATA line
  std::size_t data_line = 0;
};

PcdHeader parse_header(std::string_view bytes, const std::string& source) {
  PcdHeader h;
  LineCursor cursor(bytes);
  std::string_view line;
  std::vector<std::string_view> tokens;
  std::vector<std::string_view> sizes, types, counts;
  bool has_fields = false;
  while (true) {
    if (!cursor.next(line)) fail(source, "PCD header has no DATA line");
    const std::string where = "line " + std::to_string(cursor.line_number());
    line = trim(line);
    if (line.empty() || line.front() == '#') continue;
    split_tokens(line, tokens);
    if (tokens.empty()) continue;  // only separators
    const std::string_view key = tokens[0];
    const auto want_numbers = [&](std::uint64_t& value) {
      if (tokens.size() != 2 || !parse_count(tokens[1], value))
        fail(source, where,
             std::string(key) + " needs one non-negative count, got " + quoted(line));
    };
    if (key == "VERSION" || key == "VIEWPOINT") continue;
    if (key == "FIELDS" || key == "COLUMNS") {
      for (std::size_t i = 1; i < tokens.size(); ++i)
        h.fields.push_back({std::string(tokens[i]), {}, 1, 0, field_role(tokens[i])});
      has_fields = true;
    } else if (key == "SIZE") {
      sizes.assign(tokens.begin() + 1, tokens.end());
    } else if (key == "TYPE") {
      types.assign(tokens.begin() + 1, tokens.end());
    } else if (key == "COUNT") {
      counts.assign(tokens.begin() + 1, tokens.end());
    } else if (key == "WIDTH") {
      want_numbers(h.width);
      h.has_width = true;
    } else if (key == "HEIGHT") {
      want_numbers(h.height);
    } else if (key == "POINTS") {
      want_numbers(h.points);
      h.has_points = true;
    } else if (key == "DATA") {
      if (tokens.size() != 2)
        fail(source, where, "DATA needs one of ascii, binary, binary_compressed");
      h.data = std::string(tokens[1]);
      if (h.data != "ascii" && h.data != "binary" && h.data != "binary_compressed")
        fail(source, where, "unknown DATA kind " + quoted(tokens[1]));
      h.data_offset = cursor.offset();
      h.data_line = cursor.line_number();
      break;
    } else {
      fail(source, where, "unknown PCD header entry " + quoted(key));
    }
    // Header strings must have already been seen in order for SIZE/TYPE/COUNT to be checked.
  }
  if (!has_fields || h.fields.empty()) fail(source, "PCD header has no FIELDS");
  const std::size_t nf = h.fields.size();
  if (sizes.size() != nf)
    fail(source, "PCD header: SIZE has " + std::to_string(sizes.size()) + " entries for " +
                     std::to_string(nf) + " fields");
  if (types.size() != nf)
    fail(source, "PCD header: TYPE has " + std::to_string(types.size()) + " entries for " +
                     std::to_string(nf) + " fields");
  if (!counts.empty() && counts.size() != nf)
    fail(source, "PCD header: COUNT has " + std::to_string(counts.size()) + " entries for " +
                     std::to_string(nf) + " fields");
  std::size_t offset = 0;
  bool has_x = false, has_y = false, has_z = false;
  for (std::size_t i = 0; i < nf; ++i) {
    PcdField& f = h.fields[i];
    std::uint64_t size = 0, count = 1;
    if (!parse_count(sizes[i], size) || (size != 1 && size != 2 && size != 4 && size != 8))
      fail(source, "PCD header: field " + f.name + " has unsupported SIZE " + quoted(sizes[i]));
    if (types[i].size() != 1 || std::strchr("FUI", types[i][0]) == nullptr)
      fail(source, "PCD header: field " + f.name + " has unknown TYPE " + quoted(types[i]));
    if (!counts.empty() && (!parse_count(counts[i], count, 1 << 20) || count == 0))
      fail(source, "PCD header: field " + f.name + " has invalid COUNT " + quoted(counts[i]));
    f.type = {types[i][0], static_cast<int>(size)};
    if (f.type.kind == 'F' && size != 4 && size != 8)
      fail(source, "PCD header: float field " + f.name + " must have SIZE 4 or 8");
    f.count = count;
    f.offset = offset;
    offset += size * count;
    if (f.role != FieldRole::kIgnore && count != 1) f.role = FieldRole::kIgnore;
    has_x |= f.role == FieldRole::kX;
    has_y |= f.role == FieldRole::kY;
    has_z |= f.role == FieldRole::kZ;
  }
  if (!has_x || !has_y || !has_z) fail(source, "PCD has no x, y and z fields");
  h.point_bytes = offset;
  if (!h.has_width) fail(source, "PCD header has no WIDTH");
  if (h.height == 0 && h.width != 0) fail(source, "PCD header: HEIGHT is 0");
  if (h.width > (std::uint64_t{1} << 40) / std::max<std::uint64_t>(h.height, 1))
    fail(source, "PCD header: WIDTH x HEIGHT is too large");
  if (!h.has_points) h.points = h.width * h.height;
  if (h.points != h.width * h.height)
    fail(source, "PCD header: POINTS " + std::to_string(h.points) +
                     " disagrees with WIDTH x HEIGHT = " + std::to_string(h.width * h.height));
  return h;
}

struct Roles {
  bool intensity = false, ring = false, time = false;
};

Roles roles_of(const PcdHeader& h) {
  Roles r;
  for (const auto& f : h.fields) {
    r.intensity |= f.role == FieldRole::kIntensity;
    r.ring |= f.role == FieldRole::kRing;
    r.time |= f.role == FieldRole::kTime;
  }
  return r;
}

}  // namespace

PointCloud parse_pcd(std::string_view bytes, const std::string& source,
                     const CloudReadOptions& options, CloudFileInfo* info) {
  if (bytes.empty()) fail(source, "file is empty");
  const PcdHeader h = parse_header(bytes, source);
  const Roles roles = roles_of(h);
  CloudBuilder builder(roles.intensity, roles.ring, roles.time, options);
  if (info) {
    info->format = CloudFormat::kPcd;
    info->encoding = h.data;
    info->fields.clear();
    for (const auto& f : h.fields) info->fields.push_back(f.name);
    info->width = h.width;
    info->height = h.height;
  }
  const std::string_view data = bytes.substr(h.data_offset);
  double values[6] = {0, 0, 0, 0, 0, 0};

  if (h.data == "ascii") {
    // Each point needs at least two characters per value, so this bounds the claimed count.
    std::size_t values_per_point = 0;
    for (const auto& f : h.fields) values_per_point += f.count;
    if (h.points > data.size() / (2 * values_per_point) + 1)
      fail(source, "PCD header claims " + std::to_string(h.points) + " points but only " +
                       std::to_string(data.size()) + " bytes of ascii data follow");
    builder.reserve(h.points);
    LineCursor cursor(data);
    std::string_view line;
    std::vector<std::string_view> tokens;
    std::uint64_t read = 0;
    while (cursor.next(line)) {
      const std::string where = "line " + std::to_string(h.data_line + cursor.line_number());
      if (trim(line).empty()) continue;
      if (read == h.points)
        fail(source, where,
             "more data rows than the " + std::to_string(h.points) + " POINTS declared");
      split_tokens(line, tokens);
      if (tokens.empty()) continue;  // only separators
      if (tokens.size() != values_per_point)
        fail(source, where,
             "expected " + std::to_string(values_per_point) + " values, found " +
                 std::to_string(tokens.size()));
      std::size_t t = 0;
      for (const auto& f : h.fields) {
        for (std::size_t c = 0; c < f.count; ++c, ++t) {
          double v;
          if (!parse_double(tokens[t], v))
            fail(source, where, "not a number: " + quoted(tokens[t]));
          if (c == 0 && f.role != FieldRole::kIgnore) values[static_cast<int>(f.role)] = v;
        }
      }
      builder.add(values);
      ++read;
    }
    if (read != h.points)
      fail(source, "truncated: " + std::to_string(read) + " data rows, header declares " +
                       std::to_string(h.points));
    return builder.finish(info);
  }

  const std::size_t total_bytes = static_cast<std::size_t>(h.points) * h.point_bytes;
  std::string decompressed;
  const char* records = nullptr;
  bool structure_of_arrays = false;
  if (h.data == "binary") {
    if (h.point_bytes == 0 || h.points > data.size() / std::max<std::size_t>(h.point_bytes, 1))
      fail(source, "byte " + std::to_string(h.data_offset),
           "truncated: " + std::to_string(h.points) + " points need " +
               std::to_string(total_bytes) + " bytes of binary data, the file has " +
               std::to_string(data.size()));
    records = data.data();
  } else {
    if (data.size() < 8)
      fail(source, "byte " + std::to_string(h.data_offset),
           "truncated: binary_compressed data has no size words");
    std::uint32_t compressed_size, uncompressed_size;
    std::memcpy(&compressed_size, data.data(), 4);
    std::memcpy(&uncompressed_size, data.data() + 4, 4);
    if (compressed_size > data.size() - 8)
      fail(source, "byte " + std::to_string(h.data_offset),
           "truncated: compressed size " + std::to_string(compressed_size) + " but only " +
               std::to_string(data.size() - 8) + " bytes follow");
    if (uncompressed_size != total_bytes)
      fail(source, "byte " + std::to_string(h.data_offset + 4),
           "uncompressed size " + std::to_string(uncompressed_size) + " disagrees with " +
               std::to_string(h.points) + " points of " + std::to_string(h.point_bytes) + " bytes");
    // An LZF byte expands to at most ~88 bytes: refuse sizes the data cannot produce before
    // allocating.
    if (static_cast<std::uint64_t>(uncompressed_size) > std::uint64_t{compressed_size} * 90 + 64)
      fail(source, "byte " + std::to_string(h.data_offset + 4),
           "uncompressed size " + std::to_string(uncompressed_size) + " is impossible for " +
               std::to_string(compressed_size) + " compressed bytes");
    decompressed = lzf_decompress(data.substr(8, compressed_size), uncompressed_size, source);
    records = decompressed.data();
    structure_of_arrays = true;
  }
  builder.reserve(h.points);
  const std::size_t n = h.points;
  for (std::size_t i = 0; i < n; ++i) {
    for (const auto& f : h.fields) {
      if (f.role == FieldRole::kIgnore) continue;
      // binary: records of point_bytes; binary_compressed: each field's values stored contiguously.
      const char* p = structure_of_arrays ? records + f.offset * n + i * f.type.size * f.count
                                          : records + i * h.point_bytes + f.offset;
      values[static_cast<int>(f.role)] = load_as_double(p, f.type, false);
    }
    builder.add(values);
  }
  return builder.finish(info);
}

std::string format_pcd(const PointCloud& cloud, CloudWriteOptions::Encoding encoding) {
  const std::size_t n = cloud.size();
  struct OutField {
    const char* name;
    int size;
    char type;
  };
  std::vector<OutField> fields = {{"x", 4, 'F'}, {"y", 4, 'F'}, {"z", 4, 'F'}};
  if (cloud.has_intensity()) fields.push_back({"intensity", 4, 'F'});
  if (cloud.has_ring()) fields.push_back({"ring", 2, 'U'});
  if (cloud.has_time()) fields.push_back({"t", 4, 'F'});
  std::string out = "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS";
  for (const auto& f : fields) {
    out += ' ';
    out += f.name;
  }
  out += "\nSIZE";
  for (const auto& f : fields) {
    out += ' ';
    out += std::to_string(f.size);
  }
  out += "\nTYPE";
  for (const auto& f : fields) {
    out += ' ';
    out += f.type;
  }
  out += "\nCOUNT";
  for (std::size_t i = 0; i < fields.size(); ++i) out += " 1";
  out += "\nWIDTH " + std::to_string(n) + "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " +
         std::to_string(n) + "\nDATA ";
  using Encoding = CloudWriteOptions::Encoding;
  if (encoding == Encoding::kAscii) {
    out += "ascii\n";
    for (std::size_t i = 0; i < n; ++i) append_point_text(out, cloud, i, ' ');
    return out;
  }
  std::size_t point_bytes = 0;
  for (const auto& f : fields) point_bytes += static_cast<std::size_t>(f.size);
  if (encoding == Encoding::kBinary) {
    out += "binary\n";
    out.reserve(out.size() + n * point_bytes);
    for (std::size_t i = 0; i < n; ++i) append_point_binary(out, cloud, i);
    return out;
  }
  out += "binary_compressed\n";
  std::string soa;
  soa.reserve(n * point_bytes);
  for (int axis = 0; axis < 3; ++axis)
    for (std::size_t i = 0; i < n; ++i) append_bytes(soa, &cloud.points[i][axis], 4);
  if (cloud.has_intensity()) append_bytes(soa, cloud.intensity.data(), 4 * n);
  if (cloud.has_ring()) append_bytes(soa, cloud.ring.data(), 2 * n);
  if (cloud.has_time()) append_bytes(soa, cloud.time.data(), 4 * n);
  const std::string compressed = lzf_compress(soa);
  const auto compressed_size = static_cast<std::uint32_t>(compressed.size());
  const auto uncompressed_size = static_cast<std::uint32_t>(soa.size());
  append_bytes(out, &compressed_size, 4);
  append_bytes(out, &uncompressed_size, 4);
  out += compressed;
  return out;
}

}  // namespace scanmatch
