#include "scanmatch/io/sequence.hpp"

#include <algorithm>
#include <filesystem>

#include "scanmatch/core/error.hpp"
#include "scanmatch/io/file_util.hpp"
#include "scanmatch/io/parse_util.hpp"

namespace scanmatch {
namespace {
namespace fs = std::filesystem;

bool is_cloud_file(const fs::path& p) {
  const std::string ext = extension_without_gz(p.string());
  return ext == "pcd" || ext == "ply" || ext == "bin";
}

std::vector<std::string> cloud_files_in(const fs::path& folder) {
  std::vector<std::string> files;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder, ec))
    if (entry.is_regular_file() && is_cloud_file(entry.path()))
      files.push_back(entry.path().string());
  if (ec) fail(folder.string(), "cannot list the folder: " + ec.message());
  // Plain name order: zero-padded frame numbers (000123.pcd) sort correctly.
  std::sort(files.begin(), files.end());
  return files;
}

class FolderSequence : public SequenceSource {
 public:
  FolderSequence(std::string kind, std::string root, std::vector<std::string> files,
                 std::vector<double> times, std::optional<Trajectory> ground_truth,
                 CloudReadOptions options)
      : kind_(std::move(kind)),
        root_(std::move(root)),
        files_(std::move(files)),
        times_(std::move(times)),
        ground_truth_(std::move(ground_truth)),
        options_(options) {}

  std::size_t size() const override { return files_.size(); }

  bool next(Frame& frame) override {
    if (next_ >= files_.size()) return false;
    frame.index = next_;
    frame.timestamp = times_.empty() ? 0.1 * static_cast<double>(next_) : times_[next_];
    frame.name = files_[next_];
    frame.cloud = read_cloud(files_[next_], options_);
    ++next_;
    return true;
  }

  std::optional<Trajectory> ground_truth() const override { return ground_truth_; }

  std::string describe() const override {
    return kind_ + " " + root_ + " (" + std::to_string(files_.size()) + " frames" +
           (ground_truth_ ? ", ground truth" : "") + ")";
  }

 private:
  std::string kind_, root_;
  std::vector<std::string> files_;
  std::vector<double> times_;
  std::optional<Trajectory> ground_truth_;
  CloudReadOptions options_;
  std::size_t next_ = 0;
};

}  // namespace

std::unique_ptr<SequenceSource> open_sequence_folder(const std::string& path,
                                                     const CloudReadOptions& options) {
  const fs::path root(path);
  std::error_code ec;
  if (!fs::exists(root, ec)) fail(path, "does not exist");
  if (!fs::is_directory(root, ec)) fail(path, "is not a folder of frames");
  std::string kind = "folder";
  fs::path frames = root;
  fs::path poses, times;
  if (fs::is_directory(root / "velodyne")) {
    kind = "KITTI sequence";
    frames = root / "velodyne";
    poses = root / "poses.txt";
    times = root / "times.txt";
  } else if (fs::is_directory(root / "frames")) {
    kind = "data set";
    frames = root / "frames";
    poses = root / "poses_gt.txt";
    times = root / "times.txt";
  }
  std::vector<std::string> files = cloud_files_in(frames);
  if (files.empty()) fail(path, "holds no .pcd, .ply or .bin frames");
  std::vector<double> frame_times;
  if (!times.empty() && fs::exists(times)) {
    frame_times = read_times(times.string());
    if (frame_times.size() != files.size())
      fail(times.string(), "has " + std::to_string(frame_times.size()) + " times for " +
                               std::to_string(files.size()) + " frames");
  }
  std::optional<Trajectory> ground_truth;
  if (!poses.empty() && fs::exists(poses)) {
    ground_truth = read_trajectory(poses.string());
    if (ground_truth->size() != files.size())
      fail(poses.string(), "has " + std::to_string(ground_truth->size()) + " poses for " +
                               std::to_string(files.size()) + " frames");
    if (!ground_truth->has_timestamps() && !frame_times.empty())
      ground_truth->timestamps = frame_times;
  }
  return std::make_unique<FolderSequence>(kind, path, std::move(files), std::move(frame_times),
                                          std::move(ground_truth), options);
}

}  // namespace scanmatch
