#pragma once
// Configurations as JSON, from the one description in config_fields.hpp: every run writes the
// configuration it used (RUNDIR/config.json) and `--config FILE` loads one back, so any number can
// be reproduced. Keys are the field names, with "registration", "registration.solver" and
// "registration.loam" nested; odometry's config.json adds the exported map's options under
// "map_export". A file may give any subset (files written before "map_export" existed still
// load); unknown keys and wrong types are errors naming the file and the key.

#include <functional>
#include <string>

#include "scanmatch/odometry/odometry.hpp"
#include "scanmatch/odometry/run.hpp"
#include "scanmatch/odometry/run2d.hpp"

namespace scanmatch {

/// Everything `odometry` takes from its configuration, i.e. what RUNDIR/config.json holds: the
/// pipeline's OdometryConfig (its keys at the top level) and, of RunOptions, the exported map's
/// options (save, format, voxel size, radius: "map_export"). RunOptions' other fields (folder,
/// frame limit, quiet, stop) belong to one run and are not part of it.
struct OdometryRunConfig {
  OdometryConfig odometry;
  RunOptions output;
};

/// `register`'s configuration: both clouds are voxel-downsampled, then registered.
struct PairRegistrationOptions {
  double voxel_size = 0.1;  ///< m; 0: no downsampling
  RegistrationOptions registration;
};

/// The whole configuration as pretty-printed JSON text.
std::string odometry_config_to_json(const OdometryConfig& config);
/// Applies the keys in `json_text` on top of `base`; `source` names the input in errors.
OdometryConfig odometry_config_from_json(const std::string& json_text, const std::string& source,
                                         const OdometryConfig& base = {});
/// Reads a JSON configuration file (e.g. RUNDIR/config.json, whose "map_export" is checked and
/// left out) on top of `base`.
OdometryConfig read_odometry_config(const std::string& path, const OdometryConfig& base = {});
/// `base` with the fields whose command-line flag `was_given` taken from `given`: a --config
/// file overridden by exactly the options on the command line.
OdometryConfig override_given_flags(const OdometryConfig& base, const OdometryConfig& given,
                                    const std::function<bool(const std::string& flag)>& was_given);

/// RUNDIR/config.json: the OdometryConfig's keys and "map_export".
std::string odometry_run_config_to_json(const OdometryRunConfig& config);
/// Reads a config.json file on top of `base` (a file without "map_export" keeps base's).
OdometryRunConfig read_odometry_run_config(const std::string& path,
                                           const OdometryRunConfig& base = {});
OdometryRunConfig override_given_flags(const OdometryRunConfig& base,
                                       const OdometryRunConfig& given,
                                       const std::function<bool(const std::string&)>& was_given);

/// map2d's configuration (Map2DRunOptions: mapper, registration, grid), the same way: map2d writes
/// RUNDIR/config.json and `map2d --config FILE` loads it back. Angles are radians.
std::string map2d_config_to_json(const Map2DRunOptions& options);
Map2DRunOptions read_map2d_config(const std::string& path, const Map2DRunOptions& base = {});
Map2DRunOptions override_given_flags(const Map2DRunOptions& base, const Map2DRunOptions& given,
                                     const std::function<bool(const std::string&)>& was_given);

}  // namespace scanmatch
