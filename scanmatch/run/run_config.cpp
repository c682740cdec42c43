#include "scanmatch/run/run_config.hpp"

#include "scanmatch/config/config_json.hpp"
#include "scanmatch/io/file_util.hpp"
#include "scanmatch/run/run_config_fields.hpp"

namespace scanmatch {

OdometryConfig read_odometry_config(const std::string& path, const OdometryConfig& base) {
  OdometryRunConfig run_base;
  run_base.odometry = base;
  return read_odometry_run_config(path, run_base).odometry;
}

std::string odometry_run_config_to_json(const OdometryRunConfig& config) {
  return config_json::config_to_json(config);
}

OdometryRunConfig read_odometry_run_config(const std::string& path, const OdometryRunConfig& base) {
  return config_json::config_from_json(read_file_bytes(path), path, base);
}

OdometryRunConfig override_given_flags(const OdometryRunConfig& base,
                                       const OdometryRunConfig& given,
                                       const std::function<bool(const std::string&)>& was_given) {
  return config_json::config_override_given(base, given, was_given);
}

std::string map2d_config_to_json(const Map2DRunOptions& options) {
  return config_json::config_to_json(options);
}

Map2DRunOptions read_map2d_config(const std::string& path, const Map2DRunOptions& base) {
  return config_json::config_from_json(read_file_bytes(path), path, base);
}

Map2DRunOptions override_given_flags(const Map2DRunOptions& base, const Map2DRunOptions& given,
                                     const std::function<bool(const std::string&)>& was_given) {
  return config_json::config_override_given(base, given, was_given);
}

}  // namespace scanmatch
