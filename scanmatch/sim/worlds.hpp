#pragma once
// Procedural scenes and the paths through their free space.

#include <cstdint>
#include <optional>
#include <vector>

#include "scanmatch/sim/scene.hpp"

namespace scanmatch::sim {

struct World {
  Scene scene;
  std::vector<Eigen::Vector2d> loop;  ///< closed path through free space
  Eigen::Vector3d still_position;     ///< where still presets stand (x, y, yaw)
  /// Where a replayed trajectory starts (heading +x); the loop's start when not set.
  std::optional<Eigen::Vector2d> replay_start;
};

/// Office floor: a lobby and an end hall with desks, pillars and cabinets, joined by a straight
/// 36 m corridor with plain walls (registration is degenerate along its axis).
World make_office(std::uint64_t seed);
/// Campus street block: sloped ground, buildings with recesses and window sills, kerbs, trees,
/// parked cars, poles and fences around a 120 m x 80 m road loop.
World make_campus(std::uint64_t seed);
/// A small flat of rooms for the 2D laser: walls 1 m high, doors, furniture.
World make_rooms_2d(std::uint64_t seed);
/// A ring of office corridors for a long-range 2D laser (like Radish ACES): centre lines on a
/// 60 m x 25 m rectangle, 2.4 m wide (walls at +-kCorridorHalfWidth), plain walls broken only by
/// door recesses and side rooms at irregular spacing and a few boxes against the walls. The
/// loop goes once around, starting at (12, 0) heading +x along the bottom corridor.
World make_corridors_2d(std::uint64_t seed);
inline constexpr double kCorridorHalfWidth = 1.2;

}  // namespace scanmatch::sim
