#pragma once
// Procedural scenes and the paths through their free space.

#include <cstdint>
#include <optional>
#include <vector>

#include "scanmatch/sim/scene.hpp"

namespace scanmatch::sim {

struct World {
  Scene scene;
  std::vector<Eigen::Vector2d> loop;  ///< path through free space (see loop_closed)
  bool loop_closed = true;            ///< false: an open road driven once from its first point
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
/// A long, nearly straight two-lane country road (like KITTI raw 2011_09_26_drive_0027): gentle
/// curves (radii over 3 km), kerbs, a guard rail and fences along stretches, hedgerows of bushes,
/// trees and poles at irregular spacing, a few buildings set back with cars parked before them, a
/// sign gantry and an overpass. Only the bushes, trees, poles and buildings fix a position along
/// the road. The path (open) is the right lane's centre line, kHighwayRoadLength long, starting
/// heading about +x.
World make_highway(std::uint64_t seed);
inline constexpr double kHighwayRoadLength = 1150.0;

}  // namespace scanmatch::sim
