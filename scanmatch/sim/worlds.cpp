#include "scanmatch/sim/worlds.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "scanmatch/sim/random.hpp"

namespace scanmatch::sim {
namespace {
constexpr double kWall = 0.1;  // wall half-thickness is kWall / 2

// A wall segment from a to b (ground plane), between heights z0 and z1.
void wall(Scene& scene, Eigen::Vector2d a, Eigen::Vector2d b, double z0, double z1,
          float reflectivity = 0.6f) {
  const Eigen::Vector2d d = b - a;
  Box box;
  box.center = Eigen::Vector3d(0.5 * (a.x() + b.x()), 0.5 * (a.y() + b.y()), 0.5 * (z0 + z1));
  box.half_size = Eigen::Vector3d(0.5 * d.norm() + 0.5 * kWall, 0.5 * kWall, 0.5 * (z1 - z0));
  box.yaw = std::atan2(d.y(), d.x());
  box.reflectivity = reflectivity;
  scene.add(box);
}

// A wall along x or y with door gaps: `gaps` are (centre, width) along the wall.
void wall_with_doors(Scene& scene, Eigen::Vector2d a, Eigen::Vector2d b,
                     std::vector<std::pair<double, double>> gaps, double z0, double z1) {
  const double length = (b - a).norm();
  const Eigen::Vector2d u = (b - a) / length;
  double start = 0.0;
  std::sort(gaps.begin(), gaps.end());
  for (const auto& [centre, width] : gaps) {
    const double stop = centre - 0.5 * width;
    if (stop > start + 0.05) wall(scene, a + start * u, a + stop * u, z0, z1);
    start = centre + 0.5 * width;
  }
  if (length > start + 0.05) wall(scene, a + start * u, b, z0, z1);
}

// A closed path through `corners` (in order): straight between them, turning on arcs of `radius`
// (tighter where a side is too short for it), starting where the side from corners[0] to
// corners[1] leaves its arc, as waypoints `spacing` apart. The simulator's Catmull-Rom path
// overshoots where neighbouring waypoints are unevenly spaced: through a rectangle's four corners
// alone it bulged 10-15 m off the sides, through furniture and buildings.
std::vector<Eigen::Vector2d> rounded_loop(const std::vector<Eigen::Vector2d>& corners,
                                          double radius, double spacing) {
  const std::size_t n = corners.size();
  std::vector<Eigen::Vector2d> fine;  // arcs only: the sides are the gaps between them
  std::size_t first_side = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d& previous = corners[(i + n - 1) % n];
    const Eigen::Vector2d& corner = corners[i];
    const Eigen::Vector2d& next = corners[(i + 1) % n];
    const Eigen::Vector2d in = (corner - previous).normalized(), out = (next - corner).normalized();
    const double turn = std::atan2(in.x() * out.y() - in.y() * out.x(), in.dot(out));  // left > 0
    const double half_turn_tan = std::tan(0.5 * std::abs(turn));
    const double shortest_half = 0.5 * std::min((corner - previous).norm(), (next - corner).norm());
    const double r = std::min(radius, shortest_half / std::max(half_turn_tan, 1e-9));
    const Eigen::Vector2d start = corner - r * half_turn_tan * in;
    const Eigen::Vector2d centre = start + (turn >= 0 ? r : -r) * Eigen::Vector2d(-in.y(), in.x());
    const int steps = std::max(1, static_cast<int>(std::ceil(std::abs(turn) * r / 0.05)));
    for (int k = 0; k <= steps; ++k)
      fine.push_back(centre + Eigen::Rotation2Dd(turn * k / steps) * (start - centre));
    if (i == 0) first_side = fine.size() - 1;
  }
  std::rotate(fine.begin(), fine.begin() + static_cast<long>(first_side), fine.end());
  fine.push_back(fine.front());
  double perimeter = 0.0;
  for (std::size_t i = 1; i < fine.size(); ++i) perimeter += (fine[i] - fine[i - 1]).norm();
  const auto count = static_cast<std::size_t>(std::max(3.0, std::round(perimeter / spacing)));
  const double step = perimeter / static_cast<double>(count);
  std::vector<Eigen::Vector2d> points{fine.front()};
  double travelled = 0.0;  // along `fine` up to point i - 1
  for (std::size_t i = 1; i < fine.size() && points.size() < count; ++i) {
    const double length = (fine[i] - fine[i - 1]).norm();
    while (points.size() < count && step * static_cast<double>(points.size()) < travelled + length)
      points.push_back(fine[i - 1] +
                       (fine[i] - fine[i - 1]) *
                           ((step * static_cast<double>(points.size()) - travelled) / length));
    travelled += length;
  }
  return points;
}

void box_at(Scene& scene, double x, double y, double z0, Eigen::Vector3d size, double yaw,
            float refl) {
  Box b;
  b.center = Eigen::Vector3d(x, y, z0 + 0.5 * size.z());
  b.half_size = 0.5 * size;
  b.yaw = yaw;
  b.reflectivity = refl;
  scene.add(b);
}

// Furniture of a hall: desks and cabinets along its long walls, pillars inside, all clear of the
// central aisle (|y - aisle_y| > clear).
void furnish_hall(Scene& scene, Rng& rng, double x0, double x1, double y0, double y1,
                  double height) {
  for (double x = x0 + 1.5; x < x1 - 1.5; x += rng.uniform(2.2, 3.2)) {
    box_at(scene, x, y1 - 0.6, 0.0, {1.6, 0.8, 0.75}, rng.uniform(-0.1, 0.1), 0.5f);      // desk
    box_at(scene, x + 0.3, y0 + 0.4, 0.0, {0.9, 0.5, rng.uniform(1.2, 2.0)}, 0.0, 0.7f);  // cabinet
  }
  for (double x = x0 + 3.0; x < x1 - 2.0; x += 4.0)
    for (double y : {y0 + 2.5, y1 - 2.5}) scene.add(Cylinder{{x, y}, 0.25, 0.0, height, 0.5f});
}

// One side wall of a corridor from a to b (`outward` points away from the corridor) with doors
// at irregular spacing, each a shallow recess or the door of a small room behind the wall, and a
// box against the wall between some of them.
void corridor_wall(Scene& scene, Rng& rng, Eigen::Vector2d a, Eigen::Vector2d b,
                   Eigen::Vector2d outward, double z0, double z1) {
  const double length = (b - a).norm();
  const Eigen::Vector2d u = (b - a) / length;
  std::vector<std::pair<double, double>> doors;
  double last_end = 0.0;
  // Doors start 7 m from the ends so that the rooms of the two walls at a corner do not meet.
  for (double t = rng.uniform(7, 11); t < length - 7; t += rng.uniform(3, 9)) {
    const bool room = rng.uniform() < 0.35;
    const double door = room ? 0.9 : 1.0;
    const double half = room ? 0.5 * rng.uniform(3.0, 4.5) : 0.5 * door;
    const double depth = room ? rng.uniform(3.0, 4.0) : 0.25;
    const Eigen::Vector2d left = a + (t - half) * u, right = a + (t + half) * u;
    wall(scene, left, left + depth * outward, z0, z1);
    wall(scene, right, right + depth * outward, z0, z1);
    wall(scene, left + depth * outward, right + depth * outward, z0, z1);
    if (room) {
      const Eigen::Vector2d c = a + (t + rng.uniform(-0.5, 0.5) * half) * u + 0.6 * depth * outward;
      box_at(scene, c.x(), c.y(), z0, {1.2, 0.7, z1 - z0}, rng.uniform(0, 1.5), 0.5f);
    }
    const double start = t - half;
    if (start - last_end > 3.0 && rng.uniform() < 0.4) {
      const Eigen::Vector2d c = a + 0.5 * (last_end + start) * u - 0.3 * outward;
      box_at(scene, c.x(), c.y(), z0, {0.8, 0.8, z1 - z0}, std::atan2(u.y(), u.x()), 0.7f);
    }
    doors.emplace_back(t, door);
    last_end = t + half;
    t += half;  // the next room starts past this one
  }
  wall_with_doors(scene, a, b, doors, z0, z1);
}
}  // namespace

World make_office(std::uint64_t seed) {
  Rng rng(hash_combine(seed, 0x0FF1CE));
  World w;
  Scene& s = w.scene;
  const double h = 3.0;
  Ground floor;
  floor.half_extent = 80;
  floor.cell = 10;  // flat: large triangles suffice
  floor.reflectivity = 0.3f;
  s.set_ground(floor);
  box_at(s, 18, 0, h, {80, 30, 0.2}, 0.0, 0.4f);  // ceiling slab over everything
  // Lobby x in [-12, 0], end hall x in [36, 48], both y in [-8, 8]; corridor y in [-1.25, 1.25].
  for (double xa : {-12.0, 36.0}) {
    const double xb = xa + 12.0;
    wall(s, {xa, -8}, {xb, -8}, 0, h);
    wall(s, {xa, 8}, {xb, 8}, 0, h);
    // Outer end wall is solid; the wall facing the corridor has the corridor opening.
    const double outer = xa < 0 ? xa : xb, inner = xa < 0 ? xb : xa;
    wall(s, {outer, -8}, {outer, 8}, 0, h);
    wall_with_doors(s, {inner, -8}, {inner, 8}, {{8.0, 2.5}}, 0, h);
    furnish_hall(s, rng, xa, xb, -8, 8, h);
    // A few boxes and a side room door frame give the halls structure in every direction. One
    // draw per statement, in the order the scenes were first built with (arguments' evaluation
    // order is unspecified: draws inside one call would differ between compilers).
    for (const double y : {-5.5, 5.5}) {
      const double yaw = rng.uniform(0, 1);
      const double x = 0.5 * (xa + xb) + rng.uniform(-2, 2);
      const Eigen::Vector3d size =
          y < 0 ? Eigen::Vector3d(1.2, 1.2, 1.0) : Eigen::Vector3d(0.6, 2.0, 1.8);
      box_at(s, x, y, 0, size, yaw, 0.6f);
    }
  }
  // The corridor: plain walls, 36 m long.
  wall(s, {0, -1.25}, {36, -1.25}, 0, h, 0.65f);
  wall(s, {0, 1.25}, {36, 1.25}, 0, h, 0.65f);
  // Round each hall at y = +-4, clear of the boxes at y = +-5.5 and the pillars beside them.
  w.loop = rounded_loop({{-9, -4},
                         {-9, 4},
                         {-3, 4},
                         {-2, 0.45},
                         {38, 0.45},
                         {40, 4},
                         {45, 4},
                         {45, -4},
                         {40, -4},
                         {38, -0.45},
                         {-2, -0.45},
                         {-3, -4}},
                        1.0, 0.5);
  w.replay_start = Eigen::Vector2d(-9, -5);  // where replays always began
  w.still_position = Eigen::Vector3d(-6, 1.5, 0.3);
  s.commit();
  return w;
}

World make_campus(std::uint64_t seed) {
  Rng rng(hash_combine(seed, 0xCA4B05));
  World w;
  Scene& s = w.scene;
  Ground ground;
  ground.slope_x = 0.01;
  ground.slope_y = -0.005;
  ground.amplitude = 0.25;
  ground.wavelength = 25;
  ground.half_extent = 140;
  ground.cell = 2;
  s.set_ground(ground);
  const auto gz = [&](double x, double y) { return ground.height(x, y); };
  // Road loop: rectangle with corners (+-60, +-40); road half-width 4 m, kerbs at 4.5 m. Drives
  // follow the roads' centre lines and turn on 12 m arcs, which stay inside the crossings (3.5 m
  // in from either centre line at the apex) and end before the roadside objects begin.
  const double rx = 60, ry = 40;
  w.loop = rounded_loop({{-rx, -ry}, {rx, -ry}, {rx, ry}, {-rx, ry}}, 12.0, 2.0);
  w.replay_start = Eigen::Vector2d(-rx, -ry);  // the crossing, where replays always began
  w.still_position = Eigen::Vector3d(-20, -ry + 1.5, 0.2);
  // Kerbs on both sides of each straight road, as short segments following the ground.
  const auto kerb_line = [&](Eigen::Vector2d a, Eigen::Vector2d b) {
    const int n = static_cast<int>((b - a).norm() / 4.0);
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector2d p = a + (b - a) * ((i + 0.5) / n);
      const Eigen::Vector2d d = (b - a).normalized();
      box_at(s, p.x(), p.y(), gz(p.x(), p.y()) - 0.1, {(b - a).norm() / n - 0.02, 0.3, 0.25},
             std::atan2(d.y(), d.x()), 0.35f);
    }
  };
  for (double off : {-4.5, 4.5}) {
    kerb_line({-rx + 8, -ry + off}, {rx - 8, -ry + off});
    kerb_line({-rx + 8, ry + off}, {rx - 8, ry + off});
    kerb_line({-rx + off, -ry + 8}, {-rx + off, ry - 8});
    kerb_line({rx + off, -ry + 8}, {rx + off, ry - 8});
  }
  // Buildings outside and inside the loop, set back from the road, with recesses and sills.
  const auto building = [&](double x, double y, double sx, double sy, double yaw) {
    const double base = gz(x, y) - 1.0, height = rng.uniform(8, 20);
    box_at(s, x, y, base, {sx, sy, height + 1.0}, yaw, 0.55f);
    const Eigen::Vector2d along(std::cos(yaw), std::sin(yaw)),
        across(-std::sin(yaw), std::cos(yaw));
    // An entrance block protruding from the facade and window sills in rows.
    for (double side : {-1.0, 1.0}) {
      const Eigen::Vector2d face = Eigen::Vector2d(x, y) + side * 0.5 * sy * across;
      const Eigen::Vector2d e = face + side * 0.75 * across + rng.uniform(-0.3, 0.3) * sx * along;
      box_at(s, e.x(), e.y(), gz(e.x(), e.y()) - 0.5, {rng.uniform(3, 6), 1.5, 4.0}, yaw, 0.5f);
      for (double level = 3.0; level < height - 1.0; level += 3.2)
        for (double u = -0.5 * sx + 2.0; u < 0.5 * sx - 1.5; u += 3.0) {
          const Eigen::Vector2d c = face + u * along + side * 0.15 * across;
          box_at(s, c.x(), c.y(), base + 1.0 + level, {1.4, 0.3, 0.12}, yaw, 0.7f);
        }
    }
  };
  for (double x = -rx + 10; x < rx - 10; x += rng.uniform(22, 30)) {
    for (const double side : {-1.0, 1.0}) {  // outside the loop: below, then above
      const double yaw = rng.uniform(-0.05, 0.05), sy = rng.uniform(8, 12);
      const double sx = rng.uniform(12, 18), back = rng.uniform(0, 4);
      building(side < 0 ? x : x + 5, side * (ry + 16 + back), sx, sy, yaw);
    }
    for (const double side : {-1.0, 1.0}) {  // inside the loop
      const double sy = rng.uniform(8, 10), sx = rng.uniform(10, 14), back = rng.uniform(0, 3);
      building(side < 0 ? x + 3 : x - 2, side * (ry - 18 - back), sx, sy, 0.0);
    }
  }
  for (double y = -ry + 12; y < ry - 12; y += rng.uniform(20, 28))
    for (const double side : {-1.0, 1.0}) {  // left and right of the loop
      const double sy = rng.uniform(12, 18), sx = rng.uniform(8, 12), back = rng.uniform(0, 4);
      building(side * (rx + 16 + back), y, sx, sy, 0.0);
    }
  // Trees, poles and parked cars along the roads; a fence along part of each side.
  const auto roadside = [&](Eigen::Vector2d a, Eigen::Vector2d b, Eigen::Vector2d outward) {
    const double length = (b - a).norm();
    const Eigen::Vector2d u = (b - a) / length;
    for (double t = rng.uniform(2, 6); t < length; t += rng.uniform(9, 15)) {
      const Eigen::Vector2d p = a + t * u + outward * rng.uniform(6.5, 8.0);
      const double z = gz(p.x(), p.y());
      const double trunk = rng.uniform(2.0, 3.5);
      s.add(Cylinder{p, rng.uniform(0.12, 0.25), z - 0.2, z + trunk, 0.35f});
      s.add(Ellipsoid{Eigen::Vector3d(p.x(), p.y(), z + trunk + 1.2),
                      Eigen::Vector3d(2.0, 2.0, 1.6) * rng.uniform(0.8, 1.3), 0.25f});
    }
    for (double t = rng.uniform(5, 15); t < length; t += rng.uniform(25, 35)) {
      const Eigen::Vector2d p = a + t * u + outward * 5.2;
      s.add(Cylinder{p, 0.08, gz(p.x(), p.y()) - 0.2, gz(p.x(), p.y()) + 6.0, 0.6f});
    }
    for (double t = rng.uniform(8, 20); t < length - 8; t += rng.uniform(14, 30)) {
      const Eigen::Vector2d p = a + t * u + outward * 3.2;  // parked on the road's edge
      const double yaw = std::atan2(u.y(), u.x());
      box_at(s, p.x(), p.y(), gz(p.x(), p.y()) + 0.25, {4.4, 1.8, 0.8}, yaw, 0.8f);
      box_at(s, p.x(), p.y(), gz(p.x(), p.y()) + 1.05, {2.4, 1.6, 0.6}, yaw, 0.8f);
    }
    const double f0 = rng.uniform(0.1, 0.4) * length, f1 = f0 + rng.uniform(0.2, 0.4) * length;
    for (double t = f0; t < std::min(f1, length); t += 2.5) {
      const Eigen::Vector2d p = a + (t + 1.25) * u + outward * 9.5;
      box_at(s, p.x(), p.y(), gz(p.x(), p.y()) - 0.1, {2.45, 0.05, 1.3}, std::atan2(u.y(), u.x()),
             0.45f);
    }
  };
  roadside({-rx + 6, -ry}, {rx - 6, -ry}, {0, -1});
  roadside({-rx + 6, -ry}, {rx - 6, -ry}, {0, 1});
  roadside({-rx + 6, ry}, {rx - 6, ry}, {0, 1});
  roadside({-rx + 6, ry}, {rx - 6, ry}, {0, -1});
  roadside({-rx, -ry + 6}, {-rx, ry - 6}, {-1, 0});
  roadside({-rx, -ry + 6}, {-rx, ry - 6}, {1, 0});
  roadside({rx, -ry + 6}, {rx, ry - 6}, {1, 0});
  roadside({rx, -ry + 6}, {rx, ry - 6}, {-1, 0});
  s.commit();
  return w;
}

World make_rooms_2d(std::uint64_t seed) {
  Rng rng(hash_combine(seed, 0x2D2D));
  World w;
  Scene& s = w.scene;
  const double h = 1.0;
  // Three rooms in a row (5 m x 4 m each) and a hallway along y = 4..6.
  wall(s, {0, 0}, {15, 0}, 0, h);
  wall(s, {0, 0}, {0, 6}, 0, h);
  wall(s, {15, 0}, {15, 6}, 0, h);
  wall(s, {0, 6}, {15, 6}, 0, h);
  for (double x : {5.0, 10.0}) wall(s, {x, 0}, {x, 4}, 0, h);
  wall_with_doors(s, {0, 4}, {15, 4}, {{2.5, 1.2}, {7.5, 1.2}, {12.5, 1.2}}, 0, h);
  for (int room = 0; room < 3; ++room) {
    const double x0 = 5.0 * room;
    const double table_y = rng.uniform(0.6, 1.0), table_x = x0 + rng.uniform(0.8, 1.5);
    box_at(s, table_x, table_y, 0, {1.0, 0.6, 0.8}, 0.0, 0.5f);
    const double box_yaw = rng.uniform(0, 1.5), box_y = rng.uniform(2.0, 3.0),
                 box_x = x0 + rng.uniform(3.2, 4.2);
    box_at(s, box_x, box_y, 0, {0.5, 0.5, 0.5}, box_yaw, 0.5f);
  }
  w.loop = {{1.5, 5.0}, {2.5, 2.5},  {2.5, 5.0},  {7.5, 5.0}, {7.5, 2.2},
            {7.5, 5.0}, {12.5, 5.0}, {12.5, 2.0}, {13.5, 5.2}};
  w.still_position = Eigen::Vector3d(2.5, 2.0, 0.0);
  s.commit();
  return w;
}

World make_corridors_2d(std::uint64_t seed) {
  Rng rng(hash_combine(seed, 0xC022));
  World w;
  Scene& s = w.scene;
  // Walls reach below the floor (there is none): a tilted scan plane must not pass under them.
  const double z0 = -1.0, z1 = 2.0;
  const double lx = 60, ly = 25, r = kCorridorHalfWidth;
  // Outer walls, rooms outside the ring; inner walls, rooms inside the block the ring encloses.
  corridor_wall(s, rng, {-r, -r}, {lx + r, -r}, {0, -1}, z0, z1);
  corridor_wall(s, rng, {lx + r, -r}, {lx + r, ly + r}, {1, 0}, z0, z1);
  corridor_wall(s, rng, {lx + r, ly + r}, {-r, ly + r}, {0, 1}, z0, z1);
  corridor_wall(s, rng, {-r, ly + r}, {-r, -r}, {-1, 0}, z0, z1);
  corridor_wall(s, rng, {r, r}, {lx - r, r}, {0, 1}, z0, z1);
  corridor_wall(s, rng, {lx - r, r}, {lx - r, ly - r}, {-1, 0}, z0, z1);
  corridor_wall(s, rng, {lx - r, ly - r}, {r, ly - r}, {0, -1}, z0, z1);
  corridor_wall(s, rng, {r, ly - r}, {r, r}, {1, 0}, z0, z1);
  // Along the centre lines; waypoints 1.5 m either side of each corner make square turns, and
  // (1.5, 0), (6, 0), (12, 0), (24, 0) in a row make the start exactly straight along +x.
  w.loop = {{12, 0},    {24, 0},    {36, 0},    {48, 0},  {58.5, 0}, {60, 1.5},
            {60, 12.5}, {60, 23.5}, {58.5, 25}, {45, 25}, {30, 25},  {15, 25},
            {1.5, 25},  {0, 23.5},  {0, 12.5},  {0, 1.5}, {1.5, 0},  {6, 0}};
  w.still_position = Eigen::Vector3d(12, 0, 0.0);
  s.commit();
  return w;
}

namespace {
// The highway's layout, in metres. u is the distance along the road's centre line from the
// start of the drive, d the offset across it (positive to the left of the direction of travel).
constexpr double kLaneWidth = 3.5;        // two lanes, one each way
constexpr double kDrivingOffset = -1.75;  // the car keeps to the right lane's centre
constexpr double kSceneryBehind = 140.0;  // scenery before the start (the sensor sees back)
constexpr double kSceneryAhead = 140.0;   // and past the end of the drivable road
// The centre line swings gently (curve radii over 3 km): a long curve and a shorter bend, both
// straight at the start of the drive, so its first 85 m turn by 0.4 deg (KITTI 0027's: 0.3 deg).
constexpr double kCurveAmplitude = 6.0;
constexpr double kCurveWavelength = 1200.0;
constexpr double kBendAmplitude = 1.0;
constexpr double kBendWavelength = 600.0;

// The centre line y(u) (x = u + kRoadStartX) and its slope.
constexpr double kRoadStartX = -550.0;
double road_y(double u) {
  return kCurveAmplitude * std::sin(2 * M_PI * u / kCurveWavelength) +
         kBendAmplitude * std::sin(2 * M_PI * u / kBendWavelength);
}
double road_slope(double u) {
  return kCurveAmplitude * 2 * M_PI / kCurveWavelength * std::cos(2 * M_PI * u / kCurveWavelength) +
         kBendAmplitude * 2 * M_PI / kBendWavelength * std::cos(2 * M_PI * u / kBendWavelength);
}
// The point at offset d from the centre line at u (the offset taken along the normal), and the
// road's heading there.
Eigen::Vector2d road_point(double u, double d) {
  const Eigen::Vector2d tangent = Eigen::Vector2d(1.0, road_slope(u)).normalized();
  return Eigen::Vector2d(u + kRoadStartX, road_y(u)) +
         d * Eigen::Vector2d(-tangent.y(), tangent.x());
}
double road_heading(double u) {
  return std::atan(road_slope(u));
}
}  // namespace

World make_highway(std::uint64_t seed) {
  Rng rng(hash_combine(seed, 0x41647A));
  World w;
  Scene& s = w.scene;
  // Rolling farmland: a 0.4 % climb and a gentle swell (grades under 2 %), as KITTI's drive
  // climbs 0.4 m in its first 85 m. A strip: the sensor sees no ground past ~60 m to the side.
  Ground ground;
  ground.slope_x = 0.004;
  ground.amplitude = 0.8;
  ground.wavelength = 60;
  ground.half_extent = 760;  // the scenery spans x from -690 to 740
  ground.half_extent_y = 150;
  ground.cell = 2.5;
  s.set_ground(ground);
  const auto gz = [&](const Eigen::Vector2d& p) { return ground.height(p.x(), p.y()); };
  const double u_first = -kSceneryBehind, u_last = kHighwayRoadLength + kSceneryAhead;
  // A box of `size` (along, across, up) standing on the ground at (u, d), turned with the road.
  const auto roadside_box = [&](double u, double d, double z_above, Eigen::Vector3d size,
                                float reflectivity) {
    const Eigen::Vector2d p = road_point(u, d);
    box_at(s, p.x(), p.y(), gz(p) + z_above, size, road_heading(u), reflectivity);
  };
  // A run of boxes along the road from u0 to u1 at offset d, `piece` m each (they follow the
  // curve): kerbs, rails, walls.
  const auto along = [&](double u0, double u1, double d, double piece, double z_above,
                         double across, double height, float reflectivity) {
    for (double u = u0; u + piece <= u1; u += piece)
      roadside_box(u + 0.5 * piece, d, z_above, {piece - 0.02, across, height}, reflectivity);
  };

  // Kerbs: a low stone edge on both sides, the whole length (they fix height and the lateral
  // position, not the position along the road).
  for (double side : {-1.0, 1.0})
    along(u_first, u_last, side * (kLaneWidth + 0.15), 5.0, -0.1, 0.25, 0.22, 0.35f);

  // Guard rail on the left (oncoming) side along stretches of 100-300 m: a steel beam at
  // 0.55-0.85 m on posts every 2 m. The posts repeat at 2 m, near a car's step per frame.
  for (double u = u_first + rng.uniform(0, 80); u < u_last;) {
    const double length = rng.uniform(100, 300);
    const double end = std::min(u + length, u_last);
    const double d = kLaneWidth + 1.0;
    along(u, end, d, 4.0, 0.55, 0.08, 0.3, 0.7f);
    for (double post = u; post <= end; post += 2.0)
      roadside_box(post, d + 0.12, -0.2, {0.12, 0.12, 1.0}, 0.5f);
    u = end + rng.uniform(80, 250);
  }

  // Hedgerows along both sides, 8-13 m out, in runs of 30-150 m with gaps: bushes 1-3 m long
  // of uneven height, depth and angle, the dense low growth that lines KITTI 0027's road (a
  // quarter of its points are over 0.7 m above the road, most of them 6-16 m to the side). Trimmed
  // hedges of long straight segments were too smooth: KISS-ICP stood still over frames 1-5 and
  // ended 4.1 m short after 60 frames (0.3-0.4 m with bushes; 1.0 m on KITTI's first 60 scans).
  for (double side : {-1.0, 1.0})
    for (double u = u_first + rng.uniform(0, 20); u < u_last;) {
      const double end = std::min(u + rng.uniform(30, 150), u_last);
      const double offset = rng.uniform(8, 12);
      for (double bush = rng.uniform(1, 3); u + bush <= end; u += bush, bush = rng.uniform(1, 3)) {
        // One draw per statement: the order of evaluation of function arguments is unspecified.
        const double d = side * (offset + rng.uniform(-0.9, 0.9));
        const double depth = rng.uniform(1.2, 2.5), height = rng.uniform(1.2, 3.2);
        const double yaw = road_heading(u) + rng.uniform(-0.4, 0.4);
        const Eigen::Vector2d p = road_point(u + 0.5 * bush, d);
        box_at(s, p.x(), p.y(), gz(p) - 0.1, {1.3 * bush, depth, height}, yaw, 0.3f);
      }
      u = end + rng.uniform(5, 40);
    }

  // Trees on the verges at irregular spacing (clumps and gaps), trunk and crown: what mostly
  // fixes a scan along the road, as on KITTI's rural roads.
  for (double side : {-1.0, 1.0})
    for (double u = u_first + rng.uniform(0, 10); u < u_last;) {
      const Eigen::Vector2d p = road_point(u, side * rng.uniform(6.5, 14.0));
      const double z = gz(p), trunk = rng.uniform(2.0, 4.0);
      s.add(Cylinder{p, rng.uniform(0.12, 0.3), z - 0.2, z + trunk, 0.35f});
      s.add(Ellipsoid{Eigen::Vector3d(p.x(), p.y(), z + trunk + 1.4),
                      Eigen::Vector3d(2.2, 2.2, 1.8) * rng.uniform(0.7, 1.4), 0.25f});
      u += rng.uniform() < 0.15 ? rng.uniform(40, 90) : rng.uniform(5, 18);
    }

  // Utility poles on the right verge, 35-50 m apart, and a traffic sign now and then.
  for (double u = u_first + rng.uniform(0, 30); u < u_last; u += rng.uniform(35, 50)) {
    const Eigen::Vector2d p = road_point(u, -(kLaneWidth + 2.0));
    s.add(Cylinder{p, 0.13, gz(p) - 0.2, gz(p) + 8.5, 0.5f});
  }
  for (double u = u_first + rng.uniform(20, 120); u < u_last; u += rng.uniform(100, 250)) {
    const double d = -(kLaneWidth + 1.2);
    roadside_box(u, d, -0.2, {0.08, 0.08, 2.4}, 0.5f);  // post
    roadside_box(u, d, 1.6, {0.05, 0.8, 0.8}, 0.9f);    // plate, facing the traffic
  }

  // Field fences on either side along stretches: 2.5 m panels, 1.3 m high.
  for (double side : {-1.0, 1.0})
    for (double u = u_first + rng.uniform(0, 150); u < u_last;) {
      const double end = std::min(u + rng.uniform(60, 200), u_last);
      along(u, end, side * rng.uniform(16, 20), 2.5, -0.1, 0.05, 1.4, 0.45f);
      u = end + rng.uniform(100, 300);
    }

  // Farm houses and sheds set back from the road every 60-250 m on either side, each with a
  // car or two parked on its driveway beside the road.
  for (double u = u_first + rng.uniform(20, 80); u < u_last; u += rng.uniform(60, 250)) {
    const double side = rng.uniform() < 0.5 ? -1.0 : 1.0;
    const double d = side * rng.uniform(25, 45);
    const Eigen::Vector2d p = road_point(u, d);
    const double height = rng.uniform(5, 11), length = rng.uniform(10, 22),
                 width = rng.uniform(8, 14), yaw = road_heading(u) + rng.uniform(-0.3, 0.3);
    box_at(s, p.x(), p.y(), gz(p) - 1.0, {length, width, height + 1.0}, yaw, 0.55f);
    const int cars = 1 + static_cast<int>(rng.uniform() < 0.5);
    for (int k = 0; k < cars; ++k) {
      const double cu = u + rng.uniform(-8, 8), cd = side * (kLaneWidth + rng.uniform(3.0, 5.0));
      roadside_box(cu, cd, 0.25, {4.4, 1.8, 0.8}, 0.8f);  // body
      roadside_box(cu, cd, 1.05, {2.4, 1.6, 0.6}, 0.8f);  // cabin
    }
  }

  // A sign gantry over the road: two posts on the verges and a beam 6 m up carrying two boards.
  {
    const double u = rng.uniform(300, 400);
    for (double side : {-1.0, 1.0})
      roadside_box(u, side * (kLaneWidth + 2.5), -0.3, {0.4, 0.4, 7.3}, 0.6f);
    roadside_box(u, 0.0, 6.0, {0.5, 2 * kLaneWidth + 5.4, 0.6}, 0.6f);
    for (double d : {-kLaneWidth / 2, kLaneWidth / 2})
      roadside_box(u + 0.3, d, 5.2, {0.1, 3.0, 2.2}, 0.9f);
  }
  // An overpass: a 12 m wide deck 6.5 m up on two abutment walls beside the road.
  {
    const double u = rng.uniform(700, 800);
    for (double side : {-1.0, 1.0})
      roadside_box(u, side * (kLaneWidth + 4.0), -0.5, {12.0, 1.0, 7.5}, 0.5f);
    roadside_box(u, 0.0, 6.5, {12.0, 40.0, 1.2}, 0.5f);
  }

  for (double u = 0.0; u <= kHighwayRoadLength; u += 2.0)
    w.loop.push_back(road_point(u, kDrivingOffset));
  w.loop_closed = false;
  w.replay_start = road_point(0.0, kDrivingOffset);
  const Eigen::Vector2d still = road_point(20.0, -(kLaneWidth + 1.5));
  w.still_position = Eigen::Vector3d(still.x(), still.y(), road_heading(20.0));
  s.commit();
  return w;
}

}  // namespace scanmatch::sim
