#pragma once
// A run's whole configuration as JSON, what RUNDIR/config.json holds, from its one description
// (run/run_config_fields.hpp): every run writes the configuration it used and `--config FILE`
// loads one back, so any number can be reproduced. odometry's config.json is the OdometryConfig's
// keys (config/config_io.hpp) plus the run's: "loop_closure", "loop" and the exported map's
// options ("map_export"); map2d's nests "mapper", "grid" and "loop". A file may give any subset
// (files written before "map_export" existed still load); unknown keys and wrong types are errors
// naming the file and the key.

#include <functional>
#include <string>

#include "scanmatch/odometry/odometry_config.hpp"
#include "scanmatch/run/map2d_run.hpp"
#include "scanmatch/run/odometry_run.hpp"

namespace scanmatch {

/// Everything `odometry` takes from its configuration, i.e. what RUNDIR/config.json holds: the
/// pipeline's OdometryConfig (its keys at the top level) and, of RunOptions, the exported map's
/// options (save, format, voxel size, radius: "map_export") and loop closure's. RunOptions' other
/// fields (folder, frame limit, quiet, stop) belong to one run and are not part of it.
struct OdometryRunConfig {
  OdometryConfig odometry;
  RunOptions output;
};

/// Reads a JSON configuration file (e.g. RUNDIR/config.json, whose run keys are checked and left
/// out) on top of `base`.
OdometryConfig read_odometry_config(const std::string& path, const OdometryConfig& base = {});

/// RUNDIR/config.json: the OdometryConfig's keys and the run's.
std::string odometry_run_config_to_json(const OdometryRunConfig& config);
/// Reads a config.json file on top of `base` (a file without "map_export" keeps base's).
OdometryRunConfig read_odometry_run_config(const std::string& path,
                                           const OdometryRunConfig& base = {});
OdometryRunConfig override_given_flags(const OdometryRunConfig& base,
                                       const OdometryRunConfig& given,
                                       const std::function<bool(const std::string&)>& was_given);

/// map2d's configuration (Map2DRunOptions: mapper, registration, grid, loop), the same way: map2d
/// writes RUNDIR/config.json and `map2d --config FILE` loads it back. Angles are radians.
std::string map2d_config_to_json(const Map2DRunOptions& options);
Map2DRunOptions read_map2d_config(const std::string& path, const Map2DRunOptions& base = {});
Map2DRunOptions override_given_flags(const Map2DRunOptions& base, const Map2DRunOptions& given,
                                     const std::function<bool(const std::string&)>& was_given);

}  // namespace scanmatch
