#pragma once
// Procedural scenes and the paths through their free space.

#include <cstdint>
#include <vector>

#include "scanmatch/sim/scene.hpp"

namespace scanmatch::sim {

struct World {
  Scene scene;
  std::vector<Eigen::Vector2d> loop;  ///< closed path through free space
  Eigen::Vector3d still_position;     ///< where still presets stand (x, y, yaw)
};

/// Office floor: a lobby and an end hall with desks, pillars and cabinets, joined by a straight
/// 36 m corridor with plain walls (registration is degenerate along its axis).
World make_office(std::uint64_t seed);
/// Campus street block: sloped ground, buildings with recesses and window sills, kerbs, trees,
/// parked cars, poles and fences around a 120 m x 80 m road loop.
World make_campus(std::uint64_t seed);
/// A small flat of rooms for the 2D laser: walls 1 m high, doors, furniture.
World make_rooms_2d(std::uint64_t seed);

}  // namespace scanmatch::sim
