#pragma once
// The odometry's configuration (OdometryConfig) as JSON, from its one description
// (config/odometry_fields.hpp). Keys are the field names, with "registration",
// "registration.solver" and "registration.loam" nested. A run's whole configuration
// (RUNDIR/config.json, which adds the run's own keys) is read and written by run/run_config.hpp.

#include <functional>
#include <string>

#include "scanmatch/odometry/odometry_config.hpp"

namespace scanmatch {

/// The whole configuration as pretty-printed JSON text.
std::string odometry_config_to_json(const OdometryConfig& config);
/// Applies the keys in `json_text` on top of `base`; `source` names the input in errors.
OdometryConfig odometry_config_from_json(const std::string& json_text, const std::string& source,
                                         const OdometryConfig& base = {});
/// `base` with the fields whose command-line flag `was_given` taken from `given`: a --config
/// file overridden by exactly the options on the command line.
OdometryConfig override_given_flags(const OdometryConfig& base, const OdometryConfig& given,
                                    const std::function<bool(const std::string& flag)>& was_given);

}  // namespace scanmatch
