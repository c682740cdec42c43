#pragma once
// Pairs of 2D laser scans with an exactly known offset, taken at random places in the rooms of
// the room-2d scene: the material of the 2D paper's Table 1 (one scan pair, registered by every
// method), repeated many times.

#include <cstdint>
#include <vector>

#include "scanmatch/core/scan2d.hpp"
#include "scanmatch/io/carmen.hpp"

namespace scanmatch::sim {

struct PlanarScanPair {
  LaserScan2D reference, current;
  Pose2 truth;  ///< maps current-scan points into the reference scan's frame
};

struct PlanarPairOptions {
  std::size_t count = 1000;
  double max_translation = 0.2;             ///< m, uniform over a disc
  double max_rotation = 10.0 * M_PI / 180;  ///< rad, uniform in +-
  std::uint64_t seed = 1;
  bool noise = true;  ///< 1 % range noise and 1 % dropouts of the Neato
};

/// Scans of the Neato in room-2d, at random poses inside the three rooms (never in the hallway,
/// whose 4 m range limit makes it a degenerate corridor, nor inside furniture), each with a second
/// scan at a random offset. No motion distortion: the pair measures registration alone.
std::vector<PlanarScanPair> planar_scan_pairs(const PlanarPairOptions& options);

}  // namespace scanmatch::sim
