#pragma once
// Internal helpers shared by the text and binary readers: line splitting, number parsing and a
// cloud builder that drops (and counts) non-finite points. Not part of the public API.

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "scanmatch/core/error.hpp"
#include "scanmatch/io/cloud_io.hpp"

namespace scanmatch::io_detail {

/// Walks a text one line at a time, counting lines from 1; strips '\r'.
class LineCursor {
 public:
  explicit LineCursor(std::string_view text) : text_(text) {}
  bool next(std::string_view& line) {
    if (pos_ >= text_.size()) return false;
    const std::size_t end = text_.find('\n', pos_);
    const std::size_t stop = end == std::string_view::npos ? text_.size() : end;
    line = text_.substr(pos_, stop - pos_);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos_ = end == std::string_view::npos ? text_.size() : end + 1;
    ++line_number_;
    return true;
  }
  std::size_t line_number() const { return line_number_; }
  std::size_t offset() const { return pos_; }  ///< byte offset just past the last line read

 private:
  std::string_view text_;
  std::size_t pos_ = 0, line_number_ = 0;
};

inline bool is_separator(char c) {
  return c == ' ' || c == '\t' || c == ',' || c == ';';
}

/// Splits on spaces, tabs, commas and semicolons (runs count once).
inline void split_tokens(std::string_view line, std::vector<std::string_view>& tokens) {
  tokens.clear();
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_separator(line[i])) ++i;
    std::size_t j = i;
    while (j < line.size() && !is_separator(line[j])) ++j;
    if (j > i) tokens.push_back(line.substr(i, j - i));
    i = j;
  }
}

inline std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
    s.remove_suffix(1);
  return s;
}

/// Parses a whole token as a double ("nan", "inf" accepted); false when it is not a number.
inline bool parse_double(std::string_view token, double& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  return ec == std::errc() && end == token.data() + token.size();
}

/// Parses a non-negative integer count, refusing signs, junk and values above `limit`.
inline bool parse_count(std::string_view token, std::uint64_t& value,
                        std::uint64_t limit = std::uint64_t{1} << 40) {
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  return ec == std::errc() && end == token.data() + token.size() && value <= limit;
}

inline std::string quoted(std::string_view s) {
  std::string out = "'";
  for (char c : s.substr(0, 40)) out += (static_cast<unsigned char>(c) < 32 ? '?' : c);
  if (s.size() > 40) out += "...";
  return out + "'";
}

enum class FieldRole { kX, kY, kZ, kIntensity, kRing, kTime, kIgnore };

/// Maps a field or property name to what it fills ("t", "time", "timestamp" are the time offset).
inline FieldRole field_role(std::string_view name) {
  if (name == "x") return FieldRole::kX;
  if (name == "y") return FieldRole::kY;
  if (name == "z") return FieldRole::kZ;
  if (name == "intensity" || name == "scalar_intensity" || name == "i" || name == "remission")
    return FieldRole::kIntensity;
  if (name == "ring" || name == "laser_id" || name == "line") return FieldRole::kRing;
  if (name == "t" || name == "time" || name == "timestamp" || name == "time_offset")
    return FieldRole::kTime;
  return FieldRole::kIgnore;
}

/// Collects points with whichever optional fields exist; drops non-finite points unless asked to
/// keep them, counting them either way.
class CloudBuilder {
 public:
  CloudBuilder(bool has_intensity, bool has_ring, bool has_time, const CloudReadOptions& options)
      : has_intensity_(has_intensity),
        has_ring_(has_ring),
        has_time_(has_time),
        options_(options) {}

  void reserve(std::size_t n) {
    cloud_.points.reserve(n);
    if (has_intensity_) cloud_.intensity.reserve(n);
    if (has_ring_) cloud_.ring.reserve(n);
    if (has_time_) cloud_.time.reserve(n);
  }

  /// values[] indexed by FieldRole (kX..kTime).
  void add(const double* values) {
    ++points_in_file_;
    const bool finite =
        std::isfinite(values[0]) && std::isfinite(values[1]) && std::isfinite(values[2]);
    if (!finite) {
      ++non_finite_;
      if (!options_.keep_non_finite) return;
    }
    cloud_.points.emplace_back(static_cast<float>(values[0]), static_cast<float>(values[1]),
                               static_cast<float>(values[2]));
    if (has_intensity_) cloud_.intensity.push_back(static_cast<float>(values[3]));
    if (has_ring_) {
      const double r = values[4];
      cloud_.ring.push_back(std::isfinite(r) && r >= 0 && r <= 65535 ? static_cast<std::uint16_t>(r)
                                                                     : 0);
    }
    if (has_time_) cloud_.time.push_back(static_cast<float>(values[5]));
  }

  std::size_t points_in_file() const { return points_in_file_; }

  PointCloud finish(CloudFileInfo* info) {
    if (info) {
      info->points_in_file = points_in_file_;
      info->non_finite = non_finite_;
    }
    return std::move(cloud_);
  }

 private:
  bool has_intensity_, has_ring_, has_time_;
  CloudReadOptions options_;
  PointCloud cloud_;
  std::size_t points_in_file_ = 0, non_finite_ = 0;
};

/// Little/big-endian scalar load from unaligned bytes.
template <typename T>
inline T load_scalar(const char* p, bool big_endian) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, p, sizeof(T));
  if (big_endian)
    for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(bytes[i], bytes[sizeof(T) - 1 - i]);
  T value;
  std::memcpy(&value, bytes, sizeof(T));
  return value;
}

/// A numeric type as files describe it: 'F', 'U' or 'I' with a byte size.
struct ScalarType {
  char kind = 'F';
  int size = 4;
};

/// Reads one scalar of the given type as a double.
inline double load_as_double(const char* p, ScalarType type, bool big_endian) {
  switch (type.kind) {
    case 'F':
      return type.size == 8 ? load_scalar<double>(p, big_endian)
                            : load_scalar<float>(p, big_endian);
    case 'U':
      switch (type.size) {
        case 1:
          return static_cast<std::uint8_t>(*p);
        case 2:
          return load_scalar<std::uint16_t>(p, big_endian);
        case 4:
          return load_scalar<std::uint32_t>(p, big_endian);
        default:
          return static_cast<double>(load_scalar<std::uint64_t>(p, big_endian));
      }
    default:
      switch (type.size) {
        case 1:
          return static_cast<std::int8_t>(*p);
        case 2:
          return load_scalar<std::int16_t>(p, big_endian);
        case 4:
          return load_scalar<std::int32_t>(p, big_endian);
        default:
          return static_cast<double>(load_scalar<std::int64_t>(p, big_endian));
      }
  }
}

inline void append_bytes(std::string& out, const void* p, std::size_t n) {
  out.append(static_cast<const char*>(p), n);
}

/// Appends point i as text: x y z and whichever optional fields the cloud has, `separator` between
/// values, 9 significant digits (floats round-trip exactly), and a newline.
inline void append_point_text(std::string& out, const PointCloud& cloud, std::size_t i,
                              char separator) {
  char buffer[160];
  const Point& p = cloud.points[i];
  int len = std::snprintf(buffer, sizeof buffer, "%.9g%c%.9g%c%.9g", p.x(), separator, p.y(),
                          separator, p.z());
  out.append(buffer, static_cast<std::size_t>(len));
  if (cloud.has_intensity()) {
    len = std::snprintf(buffer, sizeof buffer, "%c%.9g", separator, cloud.intensity[i]);
    out.append(buffer, static_cast<std::size_t>(len));
  }
  if (cloud.has_ring()) {
    out += separator;
    out += std::to_string(cloud.ring[i]);
  }
  if (cloud.has_time()) {
    len = std::snprintf(buffer, sizeof buffer, "%c%.9g", separator, cloud.time[i]);
    out.append(buffer, static_cast<std::size_t>(len));
  }
  out += '\n';
}

/// Appends point i as a little-endian record: float x y z, then the optional float intensity,
/// uint16 ring and float time that the cloud has (the layout both PCD and PLY writers declare).
inline void append_point_binary(std::string& out, const PointCloud& cloud, std::size_t i) {
  append_bytes(out, cloud.points[i].data(), 12);
  if (cloud.has_intensity()) append_bytes(out, &cloud.intensity[i], 4);
  if (cloud.has_ring()) append_bytes(out, &cloud.ring[i], 2);
  if (cloud.has_time()) append_bytes(out, &cloud.time[i], 4);
}

}  // namespace scanmatch::io_detail
