#pragma once
// Opening a 2D input (a CARMEN log, a simulated 2D data set, `sim:PRESET` with a 2D sensor, a
// bag's LaserScan topic) as one list of scans: the 2D counterpart of open_sequence, beside it.

#include <string>
#include <vector>

#include "scanmatch/io/carmen.hpp"
#include "scanmatch/sim/open_sequence.hpp"

namespace scanmatch {

struct Scans2D {
  std::vector<LaserScan2D> scans;
  bool has_reference = false;  ///< the scans' poses are a reference (log-corrected or simulated)
  /// s per turn of the laser (0: unknown, no deskewing): known for `sim:`, set by the user for
  /// logs (CARMEN logs do not record it).
  double rotation_period = 0.0;
  std::string description;
};

/// A CARMEN log (.log, .log.gz), a folder holding scans.log (a simulated 2D data set),
/// `sim:PRESET` with a 2D sensor (options.simulator: seed, motion_distortion) or a bag's
/// LaserScan topic (options.topic); at most `max_scans` scans (0: all). The 2D counterpart of
/// open_sequence (scanmatch/sim/open_sequence.hpp). Throws Error naming the input and the problem.
Scans2D load_scans_2d(const std::string& spec, const SequenceOptions& options = {},
                      std::size_t max_scans = 0);

}  // namespace scanmatch
