#include "scanmatch/sim/open_scans_2d.hpp"

#include <fmt/format.h>

#include <filesystem>

#include "scanmatch/core/error.hpp"
#include "scanmatch/io/bag/bag_sequence.hpp"
#include "scanmatch/sim/simulator.hpp"

namespace scanmatch {

namespace fs = std::filesystem;

Scans2D load_scans_2d(const std::string& spec, const SequenceOptions& options,
                      std::size_t max_scans) {
  Scans2D out;
  if (is_simulator_spec(spec)) {
    sim::SimOptions o = options.simulator;
    o.preset = spec.substr(4);
    if (max_scans > 0) o.frames = max_scans;
    const sim::Simulator simulator(o);
    if (!simulator.sensor().is_2d())
      throw Error(spec + ": not a 2D preset (the 2D presets are room-2d and corridor-2d)");
    for (std::size_t i = 0; i < simulator.size(); ++i) out.scans.push_back(simulator.scan_2d(i));
    out.has_reference = true;
    if (o.motion_distortion) out.rotation_period = simulator.sensor().rotation_period();
    out.description = fmt::format("{} (simulated, seed {})", spec, o.seed);
    return out;
  }
  if (!fs::exists(spec))
    throw Error(spec + ": no such input (a CARMEN log, a 2D data set, a bag or sim:PRESET)");
  if (is_bag_path(spec)) {
    out.scans = read_bag_laser_scans(spec, options.topic, max_scans);
    if (out.scans.empty()) throw Error(spec + ": the topic holds no laser scans");
    out.description = spec;
    return out;
  }
  std::string path = spec;
  if (fs::is_directory(spec)) {
    path = (fs::path(spec) / "scans.log").string();
    if (!fs::exists(path)) throw Error(spec + ": a folder without scans.log (not a 2D data set)");
  }
  CarmenReadOptions read_options;
  read_options.infer_no_return = options.infer_no_return;
  CarmenLog log = read_carmen_log(path, read_options);
  if (log.scans.empty()) throw Error(path + ": the log holds no laser scans");
  if (max_scans > 0 && log.scans.size() > max_scans) log.scans.resize(max_scans);
  out.scans = std::move(log.scans);
  for (const LaserScan2D& s : out.scans)
    if (!s.pose.isZero()) out.has_reference = true;
  out.description = path;
  return out;
}

}  // namespace scanmatch
