// `scanmatch convert IN OUT`: point clouds between formats, trajectories between KITTI and TUM,
// CARMEN logs between FLASER and ROBOTLASER1 records. Outputs are written atomically.

#include <fmt/format.h>

#include "apps/commands.hpp"
#include "apps/file_kind.hpp"
#include "scanmatch/core/error.hpp"
#include "scanmatch/io/carmen.hpp"
#include "scanmatch/io/cloud_io.hpp"
#include "scanmatch/io/sequence.hpp"
#include "scanmatch/io/trajectory.hpp"

namespace scanmatch::cli {
namespace {

struct ConvertOptions {
  std::string input, output, encoding = "binary", format, times, record = "robotlaser1";
  bool keep_non_finite = false;
};

CloudWriteOptions::Encoding parse_encoding(const std::string& name) {
  if (name == "binary") return CloudWriteOptions::Encoding::kBinary;
  if (name == "ascii") return CloudWriteOptions::Encoding::kAscii;
  if (name == "binary_compressed") return CloudWriteOptions::Encoding::kBinaryCompressed;
  fail("--encoding",
       "unknown encoding '" + name + "' (expected ascii, binary or binary_compressed)");
}

void convert_trajectory(const ConvertOptions& o) {
  Trajectory t = read_trajectory(o.input);
  TrajectoryFormat format = t.has_timestamps() ? TrajectoryFormat::kKitti : TrajectoryFormat::kTum;
  if (o.format == "kitti")
    format = TrajectoryFormat::kKitti;
  else if (o.format == "tum")
    format = TrajectoryFormat::kTum;
  else if (!o.format.empty())
    fail("--format", "unknown trajectory format '" + o.format + "' (expected kitti or tum)");
  if (!o.times.empty()) {
    std::vector<double> times = read_times(o.times);
    if (times.size() != t.size())
      fail(o.times, "has " + std::to_string(times.size()) + " times for " +
                        std::to_string(t.size()) + " poses");
    t.timestamps = std::move(times);
  }
  write_trajectory(o.output, t, format);
  fmt::print("wrote {} poses to {} ({})\n", t.size(), o.output,
             format == TrajectoryFormat::kKitti ? "KITTI" : "TUM");
}

}  // namespace

void add_convert_command(CLI::App& app) {
  auto o = std::make_shared<ConvertOptions>();
  auto* cmd = app.add_subcommand(
      "convert",
      "Convert point clouds (PCD, PLY, BIN, XYZ/CSV), trajectories (KITTI <-> TUM) or CARMEN logs");
  cmd->add_option("IN", o->input, "Input file")->required();
  cmd->add_option("OUT", o->output, "Output file; its extension picks the cloud format")
      ->required();
  cmd->add_option("--encoding", o->encoding, "Clouds: ascii, binary or binary_compressed (PCD)")
      ->capture_default_str();
  cmd->add_option("--format", o->format,
                  "Trajectories: kitti or tum (default: the other format than the input's)");
  cmd->add_option("--times", o->times, "Trajectories: a times.txt giving each pose's timestamp");
  cmd->add_option("--record", o->record, "CARMEN: flaser or robotlaser1")->capture_default_str();
  cmd->add_flag("--keep-non-finite", o->keep_non_finite, "Clouds: keep NaN/inf points");
  cmd->callback([o] {
    switch (detect_file_kind(o->input)) {
      case FileKind::kCloud: {
        CloudReadOptions read_options;
        read_options.keep_non_finite = o->keep_non_finite;
        CloudFileInfo info;
        const PointCloud cloud = read_cloud(o->input, read_options, &info);
        write_cloud(o->output, cloud, {parse_encoding(o->encoding)});
        fmt::print("wrote {} points to {}", cloud.size(), o->output);
        if (info.non_finite > 0 && !o->keep_non_finite)
          fmt::print(" ({} non-finite points dropped)", info.non_finite);
        fmt::print("\n");
        break;
      }
      case FileKind::kTrajectory:
        convert_trajectory(*o);
        break;
      case FileKind::kCarmen: {
        const CarmenLog log = read_carmen_log(o->input);
        if (o->record != "flaser" && o->record != "robotlaser1")
          fail("--record", "unknown record '" + o->record + "' (expected flaser or robotlaser1)");
        write_carmen_log(
            o->output, log,
            o->record == "flaser" ? CarmenLaserRecord::kFlaser : CarmenLaserRecord::kRobotLaser1);
        fmt::print("wrote {} scans and {} odometry records to {}\n", log.scans.size(),
                   log.odometry.size(), o->output);
        break;
      }
      case FileKind::kSequence:
        fail(o->input, "is a folder; convert works on single files");
    }
  });
}

}  // namespace scanmatch::cli
