#pragma once
// A peer's run over the first frames of a simulated preset, through the runner every method uses.

#include <string>

#include "scanmatch/run/odometry_run.hpp"
#include "scanmatch/sim/open_sequence.hpp"

namespace scanmatch::testing {

inline RunSummary run_peer(const std::string& method, const std::string& preset,
                           std::size_t frames) {
  OdometryConfig config;
  config.method = method;
  const auto source = open_sequence("sim:" + preset);
  RunOptions options;
  options.max_frames = frames;
  options.quiet = true;
  return run_odometry(*source, config, options);
}

}  // namespace scanmatch::testing
