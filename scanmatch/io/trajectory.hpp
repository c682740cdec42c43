#pragma once
// Trajectories: KITTI poses (12 numbers a line, no timestamps) and TUM (t x y z qx qy qz qw).

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "scanmatch/core/se3.hpp"
#include "scanmatch/io/line_writer.hpp"

namespace scanmatch {

enum class TrajectoryFormat { kKitti, kTum };

struct Trajectory {
  std::vector<Pose> poses;
  std::vector<double> timestamps;  ///< empty when the file has none (KITTI)
  std::size_t size() const { return poses.size(); }
  bool has_timestamps() const { return !timestamps.empty(); }
  /// Sum of the distances between consecutive positions, metres.
  double path_length() const;
};

/// Detects the format from the content (12 vs 8 numbers a line); ".gz" allowed. Throws Error
/// naming the file and line for a wrong field count, a non-number, a non-finite value or an
/// invalid rotation.
Trajectory read_trajectory(const std::string& path);
Trajectory read_trajectory(const std::string& path, TrajectoryFormat format);

/// Parses trajectory text; `format` nullopt detects it from the first data line.
Trajectory parse_trajectory(std::string_view text, const std::string& source,
                            std::optional<TrajectoryFormat> format);

/// A times file (KITTI times.txt): one time in seconds per line (first column); `#` comments.
std::vector<double> read_times(const std::string& path);

/// Whole-file atomic write. TUM needs timestamps; without them the index is used as the time.
void write_trajectory(const std::string& path, const Trajectory& trajectory,
                      TrajectoryFormat format);

/// Appends one pose a line and flushes after each, so an interrupted run keeps what it finished.
class TrajectoryWriter {
 public:
  TrajectoryWriter(const std::string& path, TrajectoryFormat format);
  void write(const Pose& pose, double timestamp);

 private:
  TrajectoryFormat format_;
  LineWriter file_;
};

}  // namespace scanmatch
