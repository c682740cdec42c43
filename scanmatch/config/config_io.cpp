#include "scanmatch/config/config_io.hpp"

#include "scanmatch/config/config_json.hpp"
#include "scanmatch/config/odometry_fields.hpp"

namespace scanmatch {

std::string odometry_config_to_json(const OdometryConfig& config) {
  return config_json::config_to_json(config);
}

OdometryConfig odometry_config_from_json(const std::string& text, const std::string& source,
                                         const OdometryConfig& base) {
  return config_json::config_from_json(text, source, base);
}

OdometryConfig override_given_flags(const OdometryConfig& base, const OdometryConfig& given,
                                    const std::function<bool(const std::string&)>& was_given) {
  return config_json::config_override_given(base, given, was_given);
}

}  // namespace scanmatch
