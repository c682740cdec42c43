#include "scanmatch/io/bag/ros_messages.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "scanmatch/core/error.hpp"
#include "scanmatch/io/parse_util.hpp"

namespace scanmatch {
namespace {
using io_detail::load_scalar;

/// Reads one serialized message, checking every length against the bytes left. ROS 1 values are
/// packed; CDR values are aligned to their size counted from the end of the encapsulation header.
class MessageReader {
 public:
  MessageReader(const BagMessage& m, const std::string& source) : m_(m), source_(source) {
    if (m.encoding == "cdr") {
      cdr_ = true;
      if (m.data.size() < 4) fail_at(0, "CDR message shorter than its 4-byte header");
      const auto kind = static_cast<unsigned char>(m.data[1]);
      if (m.data[0] != 0 || kind > 1)
        fail_at(0, "unsupported CDR encapsulation " + std::to_string(kind) + " (plain CDR only)");
      big_endian_ = kind == 0;
      pos_ = origin_ = 4;
    } else if (m.encoding != "ros1") {
      fail(source, "topic " + m.topic,
           "unsupported message encoding '" + m.encoding + "' (ros1 and cdr are read)");
    }
  }

  [[noreturn]] void fail_at(std::size_t at, const std::string& problem) const {
    fail(source_, "topic " + m_.topic + ", " + m_.where + ", message byte " + std::to_string(at),
         problem);
  }
  std::size_t pos() const { return pos_; }
  std::size_t remaining() const { return m_.data.size() - pos_; }
  bool big_endian() const { return big_endian_; }

  void align(std::size_t n) {
    if (!cdr_) return;
    const std::size_t pad = (n - (pos_ - origin_) % n) % n;
    take(pad, "padding");
  }
  const char* take(std::size_t n, const char* what) {
    if (n > remaining())
      fail_at(pos_, std::string("truncated ") + what + ": needs " + std::to_string(n) + " bytes, " +
                        std::to_string(remaining()) + " remain");
    const char* p = m_.data.data() + pos_;
    pos_ += n;
    return p;
  }
  template <typename T>
  T scalar(const char* what) {
    align(sizeof(T));
    return load_scalar<T>(take(sizeof(T), what), big_endian_);
  }
  std::string_view string(const char* what) {
    const auto n = scalar<std::uint32_t>(what);
    std::string_view s(take(n, what), n);
    if (cdr_ && !s.empty() && s.back() == '\0') s.remove_suffix(1);
    return s;
  }
  /// A sequence's element count, refused when that many elements of at least `min_bytes` each
  /// cannot fit in the rest of the message.
  std::uint32_t count(const char* what, std::size_t min_bytes) {
    const auto n = scalar<std::uint32_t>(what);
    if (std::uint64_t{n} * min_bytes > remaining())
      fail_at(pos_, std::string(what) + ": " + std::to_string(n) + " elements cannot fit in " +
                        std::to_string(remaining()) + " bytes");
    return n;
  }
  /// std_msgs/Header; returns the stamp in ns.
  std::int64_t header() {
    if (!cdr_) scalar<std::uint32_t>("header seq");
    const std::int64_t sec = cdr_
                                 ? scalar<std::int32_t>("header stamp")
                                 : static_cast<std::int64_t>(scalar<std::uint32_t>("header stamp"));
    const std::int64_t nsec = scalar<std::uint32_t>("header stamp");
    string("header frame_id");
    return sec * 1000000000 + nsec;
  }

 private:
  const BagMessage& m_;
  const std::string& source_;
  bool cdr_ = false, big_endian_ = false;
  std::size_t pos_ = 0, origin_ = 0;
};

struct CloudField {
  std::string_view name;
  std::uint32_t offset = 0, count = 0;
  std::uint8_t datatype = 0;
};

/// PointField datatypes 1..8: INT8 UINT8 INT16 UINT16 INT32 UINT32 FLOAT32 FLOAT64.
io_detail::ScalarType scalar_type(std::uint8_t datatype) {
  static constexpr io_detail::ScalarType kTypes[] = {{'I', 1}, {'U', 1}, {'I', 2}, {'U', 2},
                                                     {'I', 4}, {'U', 4}, {'F', 4}, {'F', 8}};
  return kTypes[datatype - 1];
}

const CloudField* pick(const std::vector<CloudField>& fields,
                       std::initializer_list<std::string_view> names) {
  for (std::string_view name : names)
    for (const CloudField& f : fields)
      if (f.name == name && f.count > 0) return &f;
  return nullptr;
}

/// Converts raw per-point times to seconds since the frame start (see the header).
void times_to_seconds(std::vector<double>& t, bool integer) {
  if (integer)
    for (double& v : t) v *= 1e-9;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (double v : t)
    if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
  if (hi > 1e6)
    for (double& v : t) v -= lo;
}

PointCloud decode_point_cloud2(MessageReader& r, std::int64_t& stamp) {
  stamp = r.header();
  const auto height = r.scalar<std::uint32_t>("height");
  const auto width = r.scalar<std::uint32_t>("width");
  std::vector<CloudField> fields(r.count("fields", 13));
  for (CloudField& f : fields) {
    f.name = r.string("field name");
    const std::size_t at = r.pos();
    f.offset = r.scalar<std::uint32_t>("field offset");
    f.datatype = r.scalar<std::uint8_t>("field datatype");
    f.count = r.scalar<std::uint32_t>("field count");
    if (f.datatype < 1 || f.datatype > 8)
      r.fail_at(at, "field '" + std::string(f.name) + "' has unknown datatype " +
                        std::to_string(f.datatype));
  }
  const bool big_endian = r.scalar<std::uint8_t>("is_bigendian") != 0;
  const std::size_t step_at = r.pos();
  const auto point_step = r.scalar<std::uint32_t>("point_step");
  const auto row_step = r.scalar<std::uint32_t>("row_step");
  const std::size_t data_at = r.pos();
  const auto size = r.count("data", 1);
  const char* data = r.take(size, "data");
  r.scalar<std::uint8_t>("is_dense");
  const CloudField* role[6] = {pick(fields, {"x"}),
                               pick(fields, {"y"}),
                               pick(fields, {"z"}),
                               pick(fields, {"intensity", "reflectivity", "i", "remission"}),
                               pick(fields, {"ring", "line", "laser_id"}),
                               pick(fields, {"t", "offset_time", "time", "timestamp"})};
  if (!role[0] || !role[1] || !role[2]) r.fail_at(data_at, "PointCloud2 has no x, y and z fields");
  for (const CloudField* f : role)
    if (f && std::uint64_t{f->offset} + scalar_type(f->datatype).size > point_step)
      r.fail_at(step_at, "field '" + std::string(f->name) + "' at offset " +
                             std::to_string(f->offset) + " does not fit in point_step " +
                             std::to_string(point_step));
  const std::uint64_t n = std::uint64_t{width} * height;
  const std::uint64_t row_bytes = std::uint64_t{width} * point_step;
  const std::uint64_t rows_before_last = std::uint64_t{row_step} * (height == 0 ? 0 : height - 1);
  if (n > 0 && ((row_step < row_bytes && height > 1) || rows_before_last > size ||
                row_bytes > size - rows_before_last))
    r.fail_at(data_at, std::to_string(width) + " x " + std::to_string(height) + " points of " +
                           std::to_string(point_step) + " bytes (row_step " +
                           std::to_string(row_step) + ") do not fit in " + std::to_string(size) +
                           " bytes of data");
  const auto value = [&](const CloudField* f, std::uint64_t i) {
    const char* p = data + (i / width) * row_step + (i % width) * point_step + f->offset;
    return io_detail::load_as_double(p, scalar_type(f->datatype), big_endian);
  };
  std::vector<double> times;
  if (role[5]) {
    times.resize(n);
    for (std::uint64_t i = 0; i < n; ++i) times[i] = value(role[5], i);
    times_to_seconds(times, scalar_type(role[5]->datatype).kind != 'F');
  }
  io_detail::CloudBuilder builder(role[3] != nullptr, role[4] != nullptr, role[5] != nullptr, {});
  builder.reserve(n);
  double values[6] = {0, 0, 0, 0, 0, 0};
  for (std::uint64_t i = 0; i < n; ++i) {
    for (int k = 0; k < 5; ++k)
      if (role[k]) values[k] = value(role[k], i);
    if (role[5]) values[5] = times[i];
    builder.add(values);
  }
  return builder.finish(nullptr);
}

PointCloud decode_livox(MessageReader& r, std::int64_t& stamp) {
  stamp = r.header();
  r.scalar<std::uint64_t>("timebase");
  const std::size_t num_at = r.pos();
  const auto point_num = r.scalar<std::uint32_t>("point_num");
  r.take(4, "lidar_id and rsvd");
  const auto n = r.count("points", 19);
  if (n != point_num)
    r.fail_at(num_at, "point_num " + std::to_string(point_num) + " disagrees with " +
                          std::to_string(n) + " points");
  io_detail::CloudBuilder builder(true, true, true, {});
  builder.reserve(n);
  double values[6];
  for (std::uint32_t i = 0; i < n; ++i) {
    values[5] = r.scalar<std::uint32_t>("offset_time") * 1e-9;
    for (int k = 0; k < 3; ++k) values[k] = r.scalar<float>("point");
    values[3] = r.scalar<std::uint8_t>("reflectivity");
    r.scalar<std::uint8_t>("tag");
    values[4] = r.scalar<std::uint8_t>("line");
    builder.add(values);
  }
  return builder.finish(nullptr);
}

}  // namespace

RosMessageType ros_message_type(std::string_view type) {
  const std::string_view pkg = type.substr(0, type.find('/'));
  const std::string_view name = type.substr(type.rfind('/') + 1);
  if (pkg == "sensor_msgs" && name == "PointCloud2") return RosMessageType::kPointCloud2;
  if (pkg == "sensor_msgs" && name == "LaserScan") return RosMessageType::kLaserScan;
  if ((pkg == "livox_ros_driver" || pkg == "livox_ros_driver2") && name == "CustomMsg")
    return RosMessageType::kLivoxCustom;
  return RosMessageType::kOther;
}

PointCloud decode_cloud_message(const BagMessage& message, const std::string& source,
                                std::int64_t* stamp_ns) {
  const RosMessageType type = ros_message_type(message.type);
  if (type != RosMessageType::kPointCloud2 && type != RosMessageType::kLivoxCustom)
    fail(source, "topic " + message.topic,
         "message type '" + message.type +
             "' is not a point cloud (sensor_msgs/PointCloud2 or livox CustomMsg)");
  MessageReader reader(message, source);
  std::int64_t stamp = 0;
  PointCloud cloud = type == RosMessageType::kPointCloud2 ? decode_point_cloud2(reader, stamp)
                                                          : decode_livox(reader, stamp);
  if (stamp_ns) *stamp_ns = stamp;
  return cloud;
}

LaserScan2D decode_laser_scan(const BagMessage& message, const std::string& source) {
  if (ros_message_type(message.type) != RosMessageType::kLaserScan)
    fail(source, "topic " + message.topic,
         "message type '" + message.type + "' is not sensor_msgs/LaserScan");
  MessageReader r(message, source);
  LaserScan2D scan;
  scan.timestamp = static_cast<double>(r.header()) * 1e-9;
  float v[7];  // angle_min, angle_max, angle_increment, time_increment, scan_time, range min/max
  for (float& x : v) x = r.scalar<float>("LaserScan angles and limits");
  scan.angle_min = v[0];
  scan.angle_increment = v[2];
  scan.max_range = v[6];
  scan.ranges.resize(r.count("ranges", 4));
  for (float& x : scan.ranges) {
    x = r.scalar<float>("ranges");
    // ROS marks "no return" with NaN, inf or a value below range_min; LaserScan2D with <= 0.
    if (!std::isfinite(x) || x < v[5]) x = 0.0f;
  }
  const std::size_t at = r.pos();
  scan.remissions.resize(r.count("intensities", 4));
  for (float& x : scan.remissions) x = r.scalar<float>("intensities");
  if (!scan.remissions.empty() && scan.remissions.size() != scan.ranges.size())
    r.fail_at(at, std::to_string(scan.remissions.size()) + " intensities for " +
                      std::to_string(scan.ranges.size()) + " ranges");
  return scan;
}

}  // namespace scanmatch
