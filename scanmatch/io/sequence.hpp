#pragma once
// A sequence of frames from any source (a folder of PCD/PLY/BIN files, a KITTI sequence folder,
// the simulator), read one frame at a time so long runs need no memory for the whole sequence.

#include <cstddef>
#include <memory>
#include <optional>
#include <string>

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/io/cloud_io.hpp"
#include "scanmatch/io/trajectory.hpp"

namespace scanmatch {

struct Frame {
  std::size_t index = 0;   ///< 0-based position in the sequence
  double timestamp = 0.0;  ///< seconds (frame start); index / rate when the source has no times
  std::string name;        ///< file name or "sim:<preset>#<index>", for messages
  PointCloud cloud;        ///< points in the sensor frame, with whatever fields the source has
};

class SequenceSource {
 public:
  virtual ~SequenceSource() = default;
  /// Number of frames the source will deliver.
  virtual std::size_t size() const = 0;
  /// Reads the next frame into `frame`; false at the end. Throws Error on a bad frame.
  virtual bool next(Frame& frame) = 0;
  /// Ground-truth (or reference) poses of the frames' sensor, when the source has them.
  virtual std::optional<Trajectory> ground_truth() const { return std::nullopt; }
  /// One line for logs, e.g. "KITTI sequence /data/00 (4541 frames)".
  virtual std::string describe() const = 0;
};

/// Opens a folder: a KITTI sequence (velodyne/*.bin, optional poses.txt and times.txt), a
/// simulator data set written by `scanmatch simulate` (frames/, poses_gt.txt, times.txt), or a
/// folder of .pcd/.ply/.bin frames sorted by name. Throws Error when it holds no frames.
/// Commands open their input with open_sequence (scanmatch/sim/open_sequence.hpp), which calls
/// this for folders and also opens bags and `sim:PRESET`.
std::unique_ptr<SequenceSource> open_sequence_folder(const std::string& path,
                                                     const CloudReadOptions& options = {});

}  // namespace scanmatch
