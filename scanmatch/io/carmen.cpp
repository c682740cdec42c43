#include "scanmatch/io/carmen.hpp"

#include <algorithm>
#include <cstdio>

#include "scanmatch/core/error.hpp"
#include "scanmatch/io/file_util.hpp"
#include "scanmatch/io/parse_util.hpp"

namespace scanmatch {
namespace {
using namespace io_detail;

// A scan of more beams than this is not a laser scan (the largest real ones have a few thousand).
constexpr std::uint64_t kMaxBeams = 100000;

class LineFields {
 public:
  LineFields(const std::vector<std::string_view>& tokens, const std::string& source,
             std::string where)
      : tokens_(tokens), source_(source), where_(std::move(where)) {}
  double number(std::size_t i) const {
    need(i + 1);
    double v;
    if (!parse_double(tokens_[i], v)) fail(source_, where_, "not a number: " + quoted(tokens_[i]));
    if (!std::isfinite(v)) fail(source_, where_, "non-finite value " + quoted(tokens_[i]));
    return v;
  }
  std::size_t count(std::size_t i) const {
    need(i + 1);
    std::uint64_t v;
    if (!parse_count(tokens_[i], v, kMaxBeams))
      fail(source_, where_, "invalid beam count " + quoted(tokens_[i]));
    return static_cast<std::size_t>(v);
  }
  void need(std::size_t n) const {
    if (tokens_.size() < n)
      fail(source_, where_,
           "truncated " + std::string(tokens_[0]) + " record: " + std::to_string(tokens_.size()) +
               " fields");
  }
  void exactly(std::size_t n) const {
    if (tokens_.size() != n)
      fail(source_, where_,
           std::string(tokens_[0]) + " record has " + std::to_string(tokens_.size()) +
               " fields, its beam count implies " + std::to_string(n));
  }

 private:
  const std::vector<std::string_view>& tokens_;
  const std::string& source_;
  std::string where_;
};

/// no_return_reading over the readings themselves (reordered).
std::optional<double> no_return_in(std::vector<float>& readings) {
  // The farthest 0.5 % of the readings, nearest first: enough of them to call one a code.
  constexpr std::size_t kMinFar = 10;
  const std::size_t far = readings.size() / 200;
  if (far < kMinFar) return std::nullopt;
  const auto first = readings.end() - static_cast<std::ptrdiff_t>(far);
  std::nth_element(readings.begin(), first, readings.end());
  std::sort(first, readings.end());
  // The 2 cm that most of them fall within.
  constexpr float kCluster = 0.02f;
  std::size_t best = 0;
  float best_low = 0.0f;
  for (auto low = first, high = first; low != readings.end(); ++low) {
    while (high != readings.end() && *high - *low <= kCluster) ++high;
    const auto count = static_cast<std::size_t>(high - low);
    if (count > best) {
      best = count;
      best_low = *low;
    }
  }
  if (2 * best < far) return std::nullopt;
  // The code may spread by a centimetre or two below that (51.14-51.16 m on acapulco).
  return static_cast<double>(best_low) - static_cast<double>(kCluster);
}

void append_readings(const LaserScan2D& scan, std::vector<float>& readings) {
  for (float r : scan.ranges)
    if (std::isfinite(r) && r > 0.0f) readings.push_back(r);
}

}  // namespace

std::optional<double> no_return_reading(const std::vector<LaserScan2D>& scans) {
  std::vector<float> readings;
  for (const LaserScan2D& scan : scans) append_readings(scan, readings);
  return no_return_in(readings);
}

CarmenLog parse_carmen_log(std::string_view text, const std::string& source,
                           const CarmenReadOptions& options) {
  CarmenLog log;
  LineCursor cursor(text);
  std::string_view line;
  std::vector<std::string_view> tokens;
  std::vector<std::size_t> flaser;  // the scans read from FLASER records
  while (cursor.next(line)) {
    const std::string_view content = trim(line);
    if (content.empty() || content.front() == '#') continue;
    split_tokens(content, tokens);
    if (tokens.empty()) continue;  // only separators
    const LineFields f(tokens, source, "line " + std::to_string(cursor.line_number()));
    if (tokens[0] == "FLASER" || tokens[0] == "RLASER") {
      const std::size_t n = f.count(1);
      f.exactly(n + 11);
      LaserScan2D scan;
      scan.ranges.resize(n);
      for (std::size_t i = 0; i < n; ++i) scan.ranges[i] = static_cast<float>(f.number(2 + i));
      const double fov = options.flaser_field_of_view;
      scan.angle_min = -fov / 2;
      scan.angle_increment =
          n < 2 ? 0.0
                : (n % 2 == 1 ? fov / static_cast<double>(n - 1) : fov / static_cast<double>(n));
      scan.pose = Eigen::Vector3d(f.number(n + 2), f.number(n + 3), f.number(n + 4));
      scan.odom_pose = Eigen::Vector3d(f.number(n + 5), f.number(n + 6), f.number(n + 7));
      scan.timestamp = f.number(n + 10);
      if (tokens[0] == "FLASER") {
        flaser.push_back(log.scans.size());
        log.scans.push_back(std::move(scan));
      } else {
        ++log.ignored_lines;  // rear laser
      }
    } else if (tokens[0] == "ROBOTLASER1") {
      const std::size_t n = f.count(8);
      const std::size_t remissions = f.count(9 + n);
      f.exactly(n + remissions + 24);
      LaserScan2D scan;
      scan.angle_min = f.number(2);
      scan.angle_increment = f.number(4);
      scan.max_range = static_cast<float>(f.number(5));
      scan.ranges.resize(n);
      for (std::size_t i = 0; i < n; ++i) scan.ranges[i] = static_cast<float>(f.number(9 + i));
      scan.remissions.resize(remissions);
      for (std::size_t i = 0; i < remissions; ++i)
        scan.remissions[i] = static_cast<float>(f.number(10 + n + i));
      const std::size_t k = 10 + n + remissions;
      scan.pose = Eigen::Vector3d(f.number(k), f.number(k + 1), f.number(k + 2));
      scan.odom_pose = Eigen::Vector3d(f.number(k + 3), f.number(k + 4), f.number(k + 5));
      scan.timestamp = f.number(k + 13);
      log.scans.push_back(std::move(scan));
    } else if (tokens[0] == "ODOM") {
      f.exactly(10);
      Odometry2D odom;
      odom.pose = Eigen::Vector3d(f.number(1), f.number(2), f.number(3));
      odom.tv = f.number(4);
      odom.rv = f.number(5);
      odom.accel = f.number(6);
      odom.timestamp = f.number(9);
      log.odometry.push_back(odom);
    } else {
      ++log.ignored_lines;
    }
  }
  if (log.scans.empty() && log.odometry.empty())
    fail(source, "no FLASER, ROBOTLASER1 or ODOM records: not a CARMEN log");
  // FLASER records carry no maximum range: the log's own no-return reading sets it where the
  // readings show one below the default.
  if (options.infer_no_return && !flaser.empty()) {
    std::vector<float> readings;
    for (std::size_t i : flaser) append_readings(log.scans[i], readings);
    if (const std::optional<double> no_return = no_return_in(readings))
      for (std::size_t i : flaser)
        log.scans[i].max_range = std::min(log.scans[i].max_range, static_cast<float>(*no_return));
  }
  return log;
}

CarmenLog read_carmen_log(const std::string& path, const CarmenReadOptions& options) {
  return parse_carmen_log(read_file_bytes(path), path, options);
}

void write_carmen_log(const std::string& path, const CarmenLog& log, CarmenLaserRecord record) {
  std::string out = "# written by scanmatch\n";
  char buffer[256];
  const auto append = [&](const char* format, auto... values) {
    const int len = std::snprintf(buffer, sizeof buffer, format, values...);
    out.append(buffer, static_cast<std::size_t>(len));
  };
  // Records are interleaved by time, as a logger writes them.
  std::size_t s = 0, o = 0;
  while (s < log.scans.size() || o < log.odometry.size()) {
    const bool take_odom =
        o < log.odometry.size() &&
        (s >= log.scans.size() || log.odometry[o].timestamp <= log.scans[s].timestamp);
    if (take_odom) {
      const Odometry2D& d = log.odometry[o++];
      append("ODOM %.9g %.9g %.9g %.9g %.9g %.9g %.6f scanmatch %.6f\n", d.pose.x(), d.pose.y(),
             d.pose.z(), d.tv, d.rv, d.accel, d.timestamp, d.timestamp);
      continue;
    }
    const LaserScan2D& scan = log.scans[s++];
    const std::size_t n = scan.ranges.size();
    if (record == CarmenLaserRecord::kFlaser) {
      append("FLASER %zu", n);
      for (float r : scan.ranges) append(" %.9g", r);
      append(" %.9g %.9g %.9g %.9g %.9g %.9g %.6f scanmatch %.6f\n", scan.pose.x(), scan.pose.y(),
             scan.pose.z(), scan.odom_pose.x(), scan.odom_pose.y(), scan.odom_pose.z(),
             scan.timestamp, scan.timestamp);
    } else {
      const double fov = scan.angle_increment * static_cast<double>(n > 0 ? n - 1 : 0);
      append("ROBOTLASER1 0 %.17g %.17g %.17g %.9g 0.01 0 %zu", scan.angle_min, fov,
             scan.angle_increment, static_cast<double>(scan.max_range), n);
      for (float r : scan.ranges) append(" %.9g", r);
      append(" %zu", scan.remissions.size());
      for (float r : scan.remissions) append(" %.9g", r);
      append(" %.9g %.9g %.9g %.9g %.9g %.9g 0 0 0 0 0 %.6f scanmatch %.6f\n", scan.pose.x(),
             scan.pose.y(), scan.pose.z(), scan.odom_pose.x(), scan.odom_pose.y(),
             scan.odom_pose.z(), scan.timestamp, scan.timestamp);
    }
  }
  write_file_atomic(path, out);
}

Scan2D scan_from_laser(const LaserScan2D& scan, double min_range, double miss_range,
                       double rotation_period) {
  Scan2D out;
  const double max_range = scan.max_range;
  const double free_range = miss_range > 0.0 ? miss_range : max_range;
  out.points.reserve(scan.ranges.size());
  for (std::size_t i = 0; i < scan.ranges.size(); ++i) {
    const double range = scan.ranges[i];
    const double angle = scan.angle_min + static_cast<double>(i) * scan.angle_increment;
    const Eigen::Vector2d direction(std::cos(angle), std::sin(angle));
    if (!std::isfinite(range)) continue;
    if (range >= max_range) {
      out.misses.push_back(free_range * direction);
      continue;
    }
    if (range <= min_range) continue;
    out.points.push_back(range * direction);
    if (rotation_period > 0.0)
      out.times.push_back(rotation_period * static_cast<double>(i) *
                          std::abs(scan.angle_increment) / (2 * M_PI));
  }
  const double span = static_cast<double>(scan.ranges.size()) * std::abs(scan.angle_increment);
  out.circular = span > 2 * M_PI - 1.5 * std::abs(scan.angle_increment);
  return out;
}

}  // namespace scanmatch
