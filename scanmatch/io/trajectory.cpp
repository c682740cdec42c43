#include "scanmatch/io/trajectory.hpp"

#include "scanmatch/core/error.hpp"
#include "scanmatch/io/file_util.hpp"
#include "scanmatch/io/parse_util.hpp"

namespace scanmatch {
namespace {
using namespace io_detail;

// Rotation blocks off by more than this are refused rather than silently re-orthonormalised.
constexpr double kRotationTolerance = 1e-3;

// One pose's line, without the newline.
std::string format_line(const Pose& pose, double timestamp, TrajectoryFormat format) {
  char buffer[512];
  int len = 0;
  if (format == TrajectoryFormat::kKitti) {
    const auto r = to_kitti_row(pose);
    len = std::snprintf(buffer, sizeof buffer,
                        "%.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g",
                        r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8], r[9], r[10], r[11]);
  } else {
    const Eigen::Quaterniond q(pose.linear());
    const Eigen::Vector3d t = pose.translation();
    len = std::snprintf(buffer, sizeof buffer, "%.9f %.17g %.17g %.17g %.17g %.17g %.17g %.17g",
                        timestamp, t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
  }
  return std::string(buffer, static_cast<std::size_t>(len));
}

}  // namespace

double Trajectory::path_length() const {
  double length = 0.0;
  for (std::size_t i = 1; i < poses.size(); ++i)
    length += (poses[i].translation() - poses[i - 1].translation()).norm();
  return length;
}

Trajectory parse_trajectory(std::string_view text, const std::string& source,
                            std::optional<TrajectoryFormat> format) {
  Trajectory out;
  LineCursor cursor(text);
  std::string_view line;
  std::vector<std::string_view> tokens;
  double values[12];
  while (cursor.next(line)) {
    const std::string where = "line " + std::to_string(cursor.line_number());
    const std::string_view content = trim(line);
    if (content.empty() || content.front() == '#') continue;
    split_tokens(content, tokens);
    if (tokens.empty()) continue;  // only separators
    if (!format) {
      if (tokens.size() == 12)
        format = TrajectoryFormat::kKitti;
      else if (tokens.size() == 8)
        format = TrajectoryFormat::kTum;
      else
        fail(source, where,
             "expected 12 numbers (KITTI) or 8 (TUM: t x y z qx qy qz qw), found " +
                 std::to_string(tokens.size()));
    }
    const std::size_t expected = *format == TrajectoryFormat::kKitti ? 12 : 8;
    if (tokens.size() != expected)
      fail(source, where,
           "expected " + std::to_string(expected) + " numbers, found " +
               std::to_string(tokens.size()));
    for (std::size_t k = 0; k < expected; ++k) {
      if (!parse_double(tokens[k], values[k]))
        fail(source, where, "not a number: " + quoted(tokens[k]));
      if (!std::isfinite(values[k])) fail(source, where, "non-finite value " + quoted(tokens[k]));
    }
    Pose pose;
    if (*format == TrajectoryFormat::kKitti) {
      Eigen::Matrix4d M = Eigen::Matrix4d::Identity();
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) M(r, c) = values[4 * r + c];
      if (!is_valid_pose(M, kRotationTolerance))
        fail(source, where, "rotation block is not a rotation matrix");
      pose = from_matrix(M);
    } else {
      const Eigen::Quaterniond q(values[7], values[4], values[5], values[6]);
      if (std::abs(q.norm() - 1.0) > kRotationTolerance)
        fail(source, where,
             "quaternion is not unit length (norm " + std::to_string(q.norm()) + ")");
      pose = from_translation_quaternion(Eigen::Vector3d(values[1], values[2], values[3]), q);
      out.timestamps.push_back(values[0]);
    }
    out.poses.push_back(pose);
  }
  if (out.poses.empty()) fail(source, "no poses in the file");
  return out;
}

std::vector<double> read_times(const std::string& path) {
  const std::string text = read_file_bytes(path);
  LineCursor cursor(text);
  std::string_view line;
  std::vector<std::string_view> tokens;
  std::vector<double> times;
  while (cursor.next(line)) {
    const std::string_view content = trim(line);
    if (content.empty() || content.front() == '#') continue;
    split_tokens(content, tokens);
    if (tokens.empty()) continue;  // only separators
    double t;
    if (!parse_double(tokens[0], t) || !std::isfinite(t))
      fail(path, "line " + std::to_string(cursor.line_number()),
           "not a time in seconds: " + quoted(content));
    times.push_back(t);
  }
  return times;
}

Trajectory read_trajectory(const std::string& path) {
  return parse_trajectory(read_file_bytes(path), path, std::nullopt);
}

Trajectory read_trajectory(const std::string& path, TrajectoryFormat format) {
  return parse_trajectory(read_file_bytes(path), path, format);
}

void write_trajectory(const std::string& path, const Trajectory& trajectory,
                      TrajectoryFormat format) {
  if (trajectory.has_timestamps() && trajectory.timestamps.size() != trajectory.poses.size())
    fail(path, "cannot write: timestamps and poses differ in number");
  std::string text;
  for (std::size_t i = 0; i < trajectory.size(); ++i) {
    text += format_line(
        trajectory.poses[i],
        trajectory.has_timestamps() ? trajectory.timestamps[i] : static_cast<double>(i), format);
    text += '\n';
  }
  write_file_atomic(path, text);
}

TrajectoryWriter::TrajectoryWriter(const std::string& path, TrajectoryFormat format)
    : format_(format), file_(path) {}

void TrajectoryWriter::write(const Pose& pose, double timestamp) {
  file_.line(format_line(pose, timestamp, format_));
}

}  // namespace scanmatch
