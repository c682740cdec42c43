#include "scanmatch/io/ply.hpp"

#include <cstdio>

#include "scanmatch/io/parse_util.hpp"

namespace scanmatch {
namespace {
using namespace io_detail;

struct PlyProperty {
  std::string name;
  ScalarType type;
  bool is_list = false;
  ScalarType count_type;  // for lists
  FieldRole role = FieldRole::kIgnore;
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

bool parse_ply_type(std::string_view name, ScalarType& type) {
  struct Entry {
    const char* a;
    const char* b;
    ScalarType t;
  };
  static const Entry kTypes[] = {{"char", "int8", {'I', 1}},     {"uchar", "uint8", {'U', 1}},
                                 {"short", "int16", {'I', 2}},   {"ushort", "uint16", {'U', 2}},
                                 {"int", "int32", {'I', 4}},     {"uint", "uint32", {'U', 4}},
                                 {"float", "float32", {'F', 4}}, {"double", "float64", {'F', 8}}};
  for (const auto& e : kTypes)
    if (name == e.a || name == e.b) {
      type = e.t;
      return true;
    }
  return false;
}

}  // namespace

PointCloud parse_ply(std::string_view bytes, const std::string& source,
                     const CloudReadOptions& options, CloudFileInfo* info) {
  if (bytes.empty()) fail(source, "file is empty");
  LineCursor cursor(bytes);
  std::string_view line;
  std::vector<std::string_view> tokens;
  if (!cursor.next(line) || trim(line) != "ply")
    fail(source, "line 1", "not a PLY file (no 'ply' magic)");
  std::string format;
  std::vector<PlyElement> elements;
  bool header_done = false;
  while (cursor.next(line)) {
    const std::string where = "line " + std::to_string(cursor.line_number());
    split_tokens(trim(line), tokens);
    if (tokens.empty()) continue;
    const std::string_view key = tokens[0];
    if (key == "comment" || key == "obj_info") continue;
    if (key == "format") {
      if (tokens.size() != 3) fail(source, where, "malformed format line");
      format = std::string(tokens[1]);
      if (format != "ascii" && format != "binary_little_endian" && format != "binary_big_endian")
        fail(source, where, "unknown PLY format " + quoted(tokens[1]));
    } else if (key == "element") {
      PlyElement e;
      if (tokens.size() != 3 || !parse_count(tokens[2], e.count))
        fail(source, where, "element needs a name and a non-negative count, got " + quoted(line));
      e.name = std::string(tokens[1]);
      elements.push_back(std::move(e));
    } else if (key == "property") {
      if (elements.empty()) fail(source, where, "property before any element");
      PlyProperty p;
      if (tokens.size() == 5 && tokens[1] == "list") {
        if (!parse_ply_type(tokens[2], p.count_type) || !parse_ply_type(tokens[3], p.type) ||
            p.count_type.kind == 'F')
          fail(source, where, "unknown list property types in " + quoted(line));
        p.is_list = true;
        p.name = std::string(tokens[4]);
      } else if (tokens.size() == 3) {
        if (!parse_ply_type(tokens[1], p.type))
          fail(source, where, "unknown property type " + quoted(tokens[1]));
        p.name = std::string(tokens[2]);
      } else {
        fail(source, where, "malformed property line " + quoted(line));
      }
      if (elements.back().name == "vertex") {
        if (p.is_list)
          fail(source, where,
               "list property " + p.name + " in the vertex element is not supported");
        p.role = field_role(p.name);
      }
      elements.back().properties.push_back(std::move(p));
    } else if (key == "end_header") {
      header_done = true;
      break;
    } else {
      fail(source, where, "unknown PLY header line " + quoted(line));
    }
  }
  if (!header_done) fail(source, "PLY header has no end_header");
  if (format.empty()) fail(source, "PLY header has no format line");
  const PlyElement* vertex = nullptr;
  for (const auto& e : elements)
    if (e.name == "vertex") vertex = &e;
  if (!vertex) fail(source, "PLY has no vertex element");
  bool has[6] = {false, false, false, false, false, false};
  for (const auto& p : vertex->properties)
    if (p.role != FieldRole::kIgnore) has[static_cast<int>(p.role)] = true;
  if (!has[0] || !has[1] || !has[2])
    fail(source, "PLY vertex element has no x, y and z properties");
  if (info) {
    info->format = CloudFormat::kPly;
    info->encoding = format;
    info->fields.clear();
    for (const auto& p : vertex->properties) info->fields.push_back(p.name);
    info->width = vertex->count;
    info->height = 1;
  }
  CloudBuilder builder(has[3], has[4], has[5], options);
  double values[6] = {0, 0, 0, 0, 0, 0};
  const std::size_t body_start = cursor.offset();

  if (format == "ascii") {
    std::vector<std::string_view> row;
    for (const auto& e : elements) {
      if (e.count > bytes.size())
        fail(source, "element " + e.name + " claims " + std::to_string(e.count) +
                         " rows, more than the file's bytes");
      if (&e == vertex) builder.reserve(e.count);
      for (std::uint64_t r = 0; r < e.count; ++r) {
        if (!cursor.next(line))
          fail(source, "truncated: element " + e.name + " has " + std::to_string(r) + " of " +
                           std::to_string(e.count) + " rows");
        const std::string where = "line " + std::to_string(cursor.line_number());
        split_tokens(trim(line), row);
        if (&e != vertex) continue;  // other elements may have lists: only the row count matters
        if (row.size() != e.properties.size())
          fail(source, where,
               "expected " + std::to_string(e.properties.size()) + " values, found " +
                   std::to_string(row.size()));
        for (std::size_t k = 0; k < row.size(); ++k) {
          double v;
          if (!parse_double(row[k], v)) fail(source, where, "not a number: " + quoted(row[k]));
          if (e.properties[k].role != FieldRole::kIgnore)
            values[static_cast<int>(e.properties[k].role)] = v;
        }
        builder.add(values);
      }
      if (&e == vertex) break;
    }
    return builder.finish(info);
  }

  const bool big_endian = format == "binary_big_endian";
  std::size_t pos = body_start;
  const auto need = [&](std::size_t n, const std::string& what) {
    if (n > bytes.size() - pos)
      fail(source, "byte " + std::to_string(pos), "truncated while reading " + what);
  };
  for (const auto& e : elements) {
    std::size_t fixed_row = 0;
    bool has_list = false;
    for (const auto& p : e.properties) {
      if (p.is_list) {
        has_list = true;
        fixed_row += static_cast<std::size_t>(p.count_type.size);
      } else {
        fixed_row += static_cast<std::size_t>(p.type.size);
      }
    }
    if (fixed_row > 0 && e.count > (bytes.size() - pos) / fixed_row)
      fail(source, "byte " + std::to_string(pos),
           "truncated: element " + e.name + " claims " + std::to_string(e.count) +
               " rows of at least " + std::to_string(fixed_row) + " bytes, only " +
               std::to_string(bytes.size() - pos) + " bytes remain");
    if (&e == vertex) builder.reserve(e.count);
    if (!has_list && &e != vertex) {
      pos += fixed_row * e.count;
      continue;
    }
    for (std::uint64_t r = 0; r < e.count; ++r) {
      for (const auto& p : e.properties) {
        if (p.is_list) {
          need(static_cast<std::size_t>(p.count_type.size), e.name + " list count");
          const double count = load_as_double(bytes.data() + pos, p.count_type, big_endian);
          pos += static_cast<std::size_t>(p.count_type.size);
          if (count < 0) fail(source, "byte " + std::to_string(pos), "negative list length");
          const std::size_t list_bytes =
              static_cast<std::size_t>(count) * static_cast<std::size_t>(p.type.size);
          need(list_bytes, e.name + " list");
          pos += list_bytes;
          continue;
        }
        need(static_cast<std::size_t>(p.type.size), e.name + " row " + std::to_string(r));
        if (p.role != FieldRole::kIgnore)
          values[static_cast<int>(p.role)] = load_as_double(bytes.data() + pos, p.type, big_endian);
        pos += static_cast<std::size_t>(p.type.size);
      }
      if (&e == vertex) builder.add(values);
    }
    if (&e == vertex) break;
  }
  return builder.finish(info);
}

std::string format_ply(const PointCloud& cloud, CloudWriteOptions::Encoding encoding) {
  const bool ascii = encoding == CloudWriteOptions::Encoding::kAscii;
  std::string out = "ply\nformat ";
  out += ascii ? "ascii 1.0\n" : "binary_little_endian 1.0\n";
  out += "comment written by scanmatch\nelement vertex " + std::to_string(cloud.size()) +
         "\nproperty float x\nproperty float y\nproperty float z\n";
  if (cloud.has_intensity()) out += "property float intensity\n";
  if (cloud.has_ring()) out += "property ushort ring\n";
  if (cloud.has_time()) out += "property float t\n";
  out += "end_header\n";
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (ascii)
      append_point_text(out, cloud, i, ' ');
    else
      append_point_binary(out, cloud, i);
  }
  return out;
}

}  // namespace scanmatch
