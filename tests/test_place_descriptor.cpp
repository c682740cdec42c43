// Place descriptors and the candidate search for loop closure: scans simulated at exact poses in
// the simulator's worlds (campus for 3D, the flat of rooms for 2D) must recognise revisited places
// and the yaw between the visits, and the database must find them without scanning every entry.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <set>
#include <vector>

#include "scanmatch/core/error.hpp"
#include "scanmatch/features/place_database.hpp"
#include "scanmatch/features/place_descriptor.hpp"
#include "scanmatch/io/carmen.hpp"
#include "scanmatch/sim/motion.hpp"
#include "scanmatch/sim/random.hpp"
#include "scanmatch/sim/sensor.hpp"
#include "scanmatch/sim/worlds.hpp"
#include "test_helpers.hpp"

using namespace scanmatch;

namespace {

constexpr double kSector = 2 * M_PI / 60;  // the default sector width

double wrap_angle(double a) {
  return std::remainder(a, 2 * M_PI);
}

// The campus world of the dynamic-outdoor and car presets (seed 1), built once.
const sim::World& campus() {
  static const sim::World world = sim::make_campus(1);
  return world;
}
const sim::World& rooms() {
  static const sim::World world = sim::make_rooms_2d(1);
  return world;
}

// A frame of `sensor` standing still at (x, y, heading `yaw`) on the campus ground, `height`
// above it: the sensor's rays cast into the scene, with its range noise. Points in the sensor
// frame.
PointCloud campus_frame(double x, double y, double yaw, std::uint64_t seed = 1,
                        const char* sensor_name = "vlp16", double height = 1.8) {
  const sim::World& world = campus();
  const sim::SensorModel& sensor = sim::sensor_model(sensor_name);
  sim::RayPattern pattern;
  sim::generate_pattern(sensor, seed, pattern);
  const Eigen::Vector3d origin(x, y, world.scene.ground()->height(x, y) + height);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  PointCloud cloud;
  for (std::size_t k = 0; k < pattern.directions.size(); ++k) {
    const Eigen::Vector3d d = pattern.directions[k].cast<double>();
    const sim::RayHit hit = world.scene.raycast(origin, R * d, sensor.min_range, sensor.max_range);
    if (!hit.hit) continue;
    sim::Rng rng = sim::ray_rng(seed, 7, k);
    cloud.points.push_back((d * (hit.range + sensor.range_noise * rng.normal())).cast<float>());
  }
  return cloud;
}

// A scan of the neato laser (4 m, 1-degree beams, 1 % range noise) 0.2 m above the floor of the
// flat at (x, y, heading yaw), over `fov_deg` centred on the heading, as the 2D methods get it.
Scan2D room_scan(double x, double y, double yaw, double fov_deg = 360, std::uint64_t seed = 1) {
  const sim::SensorModel& neato = sim::sensor_model("neato");
  LaserScan2D laser;
  laser.max_range = static_cast<float>(neato.max_range);
  laser.angle_increment = M_PI / 180;
  const int beams = fov_deg >= 360 ? 360 : static_cast<int>(fov_deg) + 1;
  laser.angle_min = fov_deg >= 360 ? 0.0 : -0.5 * fov_deg * M_PI / 180;
  for (int b = 0; b < beams; ++b) {
    const double a = yaw + laser.angle_min + b * laser.angle_increment;
    const sim::RayHit hit = rooms().scene.raycast({x, y, 0.2}, {std::cos(a), std::sin(a), 0.0},
                                                  neato.min_range, neato.max_range);
    sim::Rng rng = sim::ray_rng(seed, 11, static_cast<std::uint64_t>(b));
    laser.ranges.push_back(
        hit.hit ? static_cast<float>(hit.range * (1 + neato.range_noise_fraction * rng.normal()))
                : laser.max_range);
  }
  return scan_from_laser(laser);
}

PlaceDescriptor2DOptions neato_options() {
  PlaceDescriptor2DOptions o;
  o.max_range = 4.0;  // the laser's reach
  return o;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// 3D

TEST(PlaceDescriptor3D, SamePlaceTurnedAndShiftedMatchesWithItsYaw) {
  const PlaceDescriptor3D start = make_place_descriptor(campus_frame(-20, -40, 0.0));
  ASSERT_FALSE(start.empty());
  EXPECT_EQ(start.rings, 20);
  EXPECT_EQ(start.sectors, 60);
  // The same place 1 m on, turned by various yaws (the campus road runs along x at y = -40).
  for (const double turn_deg : {90.0, -135.0, 33.0}) {
    const double turn = turn_deg * M_PI / 180;
    const PlaceDescriptor3D revisit =
        make_place_descriptor(campus_frame(-19.2, -39.4, turn, /*seed=*/2));
    const PlaceMatch m = compare(revisit, start);
    std::printf("[ place3d ] same place, turned %+.0f deg, moved 1 m: distance %.3f, yaw %+.1f\n",
                turn_deg, m.distance, m.yaw * 180 / M_PI);
    EXPECT_LT(m.distance, 0.25) << turn_deg;
    EXPECT_LT(std::abs(wrap_angle(m.yaw - turn)), kSector) << turn_deg;
    // The other way round: the candidate's heading in the query's frame.
    EXPECT_LT(std::abs(wrap_angle(compare(start, revisit).yaw + turn)), kSector) << turn_deg;
  }
  // Places 30 m and more away along the same road, and on the other roads.
  const std::pair<double, double> elsewhere[] = {{10, -40}, {40, -40}, {-60, 0}, {20, 40}};
  const double same =
      compare(make_place_descriptor(campus_frame(-19.2, -39.4, 1.0, 2)), start).distance;
  for (const auto& [x, y] : elsewhere) {
    const PlaceMatch m = compare(make_place_descriptor(campus_frame(x, y, 0.7, 3)), start);
    std::printf("[ place3d ] (%.0f, %.0f), %.0f m away: distance %.3f\n", x, y,
                std::hypot(x + 20, y + 40), m.distance);
    EXPECT_GT(m.distance, same + 0.1) << x << ", " << y;
  }
}

TEST(PlaceDescriptor3D, DatabaseFindsTheStartWhenTheLoopCloses) {
  // A car drives once round the campus road loop (~390 m), a frame every 4 m, heading along the
  // road, then arrives near the start again.
  const sim::GroundPath path(campus().loop, true);
  const double step = 4.0;
  const auto frame_at = [&](double s, std::uint64_t seed) {
    const Eigen::Vector2d p = path.position(s);
    return make_place_descriptor(campus_frame(p.x(), p.y(), path.heading(s), seed));
  };
  PlaceDatabase3D database;
  std::vector<double> arc;
  for (double s = 0; s < path.length() - 2.0; s += step) {
    EXPECT_EQ(database.add(frame_at(s, arc.size() + 1)), arc.size());
    arc.push_back(s);
  }
  ASSERT_GT(database.size(), 60u);  // past a tree build (every 50) with some entries after it
  const std::size_t exclude = 20;
  // Back at the start, 1.3 m past it and 0.6 m to the side.
  const double s_return = path.length() + 1.3;
  const Eigen::Vector2d p = path.position(s_return);
  const Eigen::Vector2d side(-std::sin(path.heading(s_return)), std::cos(path.heading(s_return)));
  const Eigen::Vector2d q = p + 0.6 * side;
  const PlaceDescriptor3D query =
      make_place_descriptor(campus_frame(q.x(), q.y(), path.heading(s_return) + 0.3, 999));
  const std::vector<PlaceCandidate> found = database.query(query, exclude, 5);
  ASSERT_FALSE(found.empty());
  for (const PlaceCandidate& c : found) {
    std::printf("[ place3d ] loop query: entry %zu (%.1f m from the query) distance %.3f\n",
                c.index, (path.position(arc[c.index]) - q).norm(), c.distance);
    EXPECT_LT(c.index, database.size() - exclude);
  }
  for (std::size_t i = 1; i < found.size(); ++i)
    EXPECT_LE(found[i - 1].distance, found[i].distance);
  // The best candidate is the start (within a frame spacing) and knows the extra 0.3 rad turn.
  const Eigen::Vector2d best = path.position(arc[found[0].index]);
  EXPECT_LT((best - q).norm(), step);
  const double heading_there = path.heading(arc[found[0].index]);
  EXPECT_LT(std::abs(wrap_angle(found[0].yaw - (path.heading(s_return) + 0.3 - heading_there))),
            kSector);
  // Excluding all but the first 3 entries: only those may come back.
  for (const PlaceCandidate& c : database.query(query, database.size() - 3, 10))
    EXPECT_LT(c.index, 3u);
  EXPECT_TRUE(database.query(query, database.size(), 10).empty());
}

// ---------------------------------------------------------------------------------------------
// 2D

namespace {
struct Place2D {
  double x, y;
};
// Places 1 m apart over the flat's free floor (not inside furniture: nothing closer than 0.35 m).
std::vector<Place2D> flat_places() {
  std::vector<Place2D> places;
  for (double y : {1.0, 2.0, 3.0, 5.0})
    for (double x = 1.0; x < 15.0; x += 1.0) {
      if (std::fmod(x, 5.0) == 0.0) continue;  // the room walls
      const Scan2D s = room_scan(x, y, 0.0);
      double nearest = std::numeric_limits<double>::infinity();
      for (const Eigen::Vector2d& p : s.points) nearest = std::min(nearest, p.norm());
      if (nearest > 0.35) places.push_back({x, y});
    }
  return places;
}

// Each place scanned at one heading, then revisited `offset` metres off at another heading
// (within +-max_turn of the first): how often the right place ranks first, and the yaw error then.
// With `by_database` the places are found through a PlaceDatabase2D (ring keys, then compare);
// otherwise compare() ranks every place (what the descriptor itself can tell apart).
struct Revisits {
  std::size_t places = 0, first = 0, yaw_within_sector = 0;
};
Revisits revisit_flat(double fov_deg_stored, double fov_deg_query, double max_turn, double offset,
                      bool by_database = true) {
  const std::vector<Place2D> places = flat_places();
  sim::Rng rng(42);
  PlaceDatabase2D database;
  std::vector<double> heading;
  for (const Place2D& p : places) {
    heading.push_back(rng.uniform(-M_PI, M_PI));
    database.add(make_place_descriptor(room_scan(p.x, p.y, heading.back(), fov_deg_stored, 1),
                                       neato_options()));
  }
  Revisits r;
  r.places = places.size();
  for (std::size_t i = 0; i < places.size(); ++i) {
    const double turn = rng.uniform(-max_turn, max_turn);
    const double direction = rng.uniform(-M_PI, M_PI);
    const PlaceDescriptor2D query = make_place_descriptor(
        room_scan(places[i].x + offset * std::cos(direction),
                  places[i].y + offset * std::sin(direction), heading[i] + turn, fov_deg_query, 2),
        neato_options());
    PlaceCandidate best;
    if (by_database) {
      const std::vector<PlaceCandidate> found = database.query(query, 0, 3);
      if (found.empty()) continue;
      best = found[0];
    } else {
      for (std::size_t j = 0; j < database.size(); ++j) {
        const PlaceMatch m = compare(query, database.at(j));
        if (m.distance < best.distance) best = {j, m.distance, m.yaw};
      }
    }
    if (best.index != i) continue;
    ++r.first;
    r.yaw_within_sector += std::abs(wrap_angle(best.yaw - turn)) < kSector;
  }
  std::printf(
      "[ place2d ] %3.0f-degree queries %.2f m off, turned up to %3.0f deg, on %3.0f-degree scans "
      "(%s): right "
      "place first %zu/%zu, yaw within a sector %zu\n",
      fov_deg_query, offset, max_turn * 180 / M_PI, fov_deg_stored,
      by_database ? "database" : "all compared", r.first, r.places, r.yaw_within_sector);
  return r;
}
}  // namespace

TEST(PlaceDescriptor2D, SamePlaceWithAnotherHeadingMatchesWithItsYaw) {
  const PlaceDescriptor2D here = make_place_descriptor(room_scan(7.3, 2.4, 0.2), neato_options());
  const PlaceDescriptor2D turned =
      make_place_descriptor(room_scan(7.4, 2.3, 0.2 + 2.0, 360, 2), neato_options());
  const PlaceMatch m = compare(turned, here);
  EXPECT_LT(std::abs(wrap_angle(m.yaw - 2.0)), kSector);
  // The same spot in the other two rooms (same size, other furniture) and in the hallway.
  for (const Place2D& p : {Place2D{2.3, 2.4}, Place2D{12.3, 2.4}, Place2D{7.3, 5.0}}) {
    const PlaceMatch other =
        compare(make_place_descriptor(room_scan(p.x, p.y, 0.9, 360, 3), neato_options()), here);
    std::printf("[ place2d ] same place %.3f, (%.1f, %.1f) %.3f\n", m.distance, p.x, p.y,
                other.distance);
    // 2D distances are small (the free-space columns change gradually); what counts is the order.
    // The same spot in another room is only furniture apart: 0.28 m off, this order failed.
    EXPECT_GT(other.distance, m.distance);
  }
}

TEST(PlaceDescriptor2D, RightPlaceRanksFirstOnRevisits) {
  // The three rooms are alike but for their furniture, and near walls turn the view as the robot
  // moves: revisits within 0.15 m (printed for 0.3 m, where the rooms start to alias).
  const Revisits full = revisit_flat(360, 360, M_PI, 0.15);
  ASSERT_GT(full.places, 30u);
  EXPECT_GE(full.first, full.places * 9 / 10);
  EXPECT_GE(full.yaw_within_sector, full.first * 9 / 10);
  revisit_flat(360, 360, M_PI, 0.3);
}

TEST(PlaceDescriptor2D, HalfCircleScansRecogniseTheirPlace) {
  // A 180-degree laser (SICK-like) fills half the sectors; revisits turn up to 30 degrees, so at
  // least 150 of the 180 degrees are seen both times.
  const Revisits half = revisit_flat(180, 180, M_PI / 6, 0.1);
  EXPECT_GE(half.first, half.places * 65 / 100);
  EXPECT_GE(half.yaw_within_sector, half.first * 9 / 10);
  revisit_flat(180, 180, M_PI / 3, 0.1);  // printed: up to 60 degrees
  // Half-circle queries against full-circle scans, any heading: compare() finds the place (the
  // ring key of half a view differs from the full view's, so this is no case for the database).
  const Revisits mixed = revisit_flat(360, 180, M_PI, 0.1, false);
  EXPECT_GE(mixed.first, mixed.places * 7 / 10);
  EXPECT_GE(mixed.yaw_within_sector, mixed.first * 9 / 10);
  revisit_flat(360, 180, M_PI, 0.1, true);  // printed
  const PlaceDescriptor2D half_scan =
      make_place_descriptor(room_scan(2.5, 2.0, 0.0, 180), neato_options());
  EXPECT_NEAR(static_cast<double>(half_scan.used_columns()), 30.0, 1.0);
}

// ---------------------------------------------------------------------------------------------
// Bad input, options, the database's search

TEST(PlaceDescriptor, EmptyAndNonFiniteInputMatchesNothing) {
  const PlaceDescriptor3D empty = make_place_descriptor(PointCloud{});
  EXPECT_TRUE(empty.empty());
  PointCloud junk;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  junk.points = {{nan, 1, 1}, {1, inf, 0}, {1, 1, nan}, {500, 0, 0}};  // the last beyond 80 m
  EXPECT_TRUE(make_place_descriptor(junk).empty());
  const PlaceDescriptor3D real = make_place_descriptor(campus_frame(-20, -40, 0.0));
  EXPECT_EQ(compare(empty, real).distance, 1.0);
  EXPECT_EQ(compare(real, empty).distance, 1.0);
  EXPECT_EQ(compare(empty, empty).distance, 1.0);
  EXPECT_NEAR(compare(real, real).distance, 0.0, 1e-9);
  EXPECT_NEAR(compare(real, real).yaw, 0.0, 1e-9);
  // NaN points among real ones are skipped: the descriptor is that of the real ones alone.
  PointCloud mixed = campus_frame(-20, -40, 0.0);
  for (std::size_t i = 0; i < mixed.size(); i += 10) mixed.points[i] = Point(nan, nan, nan);
  PointCloud kept;
  for (const Point& p : mixed.points)
    if (p.allFinite()) kept.points.push_back(p);
  EXPECT_EQ(make_place_descriptor(mixed).cells, make_place_descriptor(kept).cells);

  Scan2D empty_scan;
  EXPECT_TRUE(make_place_descriptor(empty_scan).empty());
  Scan2D nan_scan;
  nan_scan.points = {{std::nan(""), 1.0}, {1.0, std::numeric_limits<double>::infinity()}};
  EXPECT_TRUE(make_place_descriptor(nan_scan).empty());
  // Empty descriptors in and against a database: no candidates, no crash.
  PlaceDatabase3D database;
  database.add(empty);
  database.add(real);
  database.add(empty);
  EXPECT_TRUE(database.query(empty, 0, 5).empty());
  const std::vector<PlaceCandidate> found = database.query(real, 0, 5);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].index, 1u);
  PlaceDescriptorOptions coarse;
  coarse.rings = 10;
  EXPECT_EQ(compare(make_place_descriptor(campus_frame(-20, -40, 0.0), coarse), real).distance,
            1.0);
  EXPECT_THROW(database.add(make_place_descriptor(campus_frame(-20, -40, 0.0), coarse)), Error);
  coarse.sectors = 0;
  EXPECT_THROW(make_place_descriptor(PointCloud{}, coarse), Error);
}

namespace {
// Random outdoor-like descriptors: points spread to a random reach, random object heights.
std::vector<PlaceDescriptor3D> random_descriptors(std::size_t count, std::uint64_t seed) {
  sim::Rng rng(seed);
  std::vector<PlaceDescriptor3D> out;
  PointCloud cloud;
  for (std::size_t i = 0; i < count; ++i) {
    cloud.points.clear();
    const double reach = rng.uniform(10, 80), crowd = rng.uniform(0.2, 1.0);
    for (int k = 0; k < 400; ++k) {
      const double r = reach * std::pow(rng.uniform(), crowd), a = rng.uniform(0, 2 * M_PI);
      cloud.points.emplace_back(r * std::cos(a), r * std::sin(a), rng.uniform(-1.8, 6.0));
    }
    out.push_back(make_place_descriptor(cloud));
  }
  return out;
}
}  // namespace

TEST(PlaceDescriptor, DatabaseSearchesTheTreeAndTheNewestEntriesLikeBruteForce) {
  // Rebuilt every 50: the last 30 entries are searched by brute force.
  const std::vector<PlaceDescriptor3D> entries =
      random_descriptors(scanmatch::testing::sanitized() ? 1030 : 5030, 7);
  PlaceDatabaseOptions options;
  options.key_candidates = 10;
  PlaceDatabase3D database(options);
  for (const PlaceDescriptor3D& d : entries) database.add(d);
  const std::vector<PlaceDescriptor3D> queries = random_descriptors(40 + 30, 8);
  const std::size_t exclude = 12;
  const std::size_t end = database.size() - exclude;

  // The candidates are the key_candidates entries nearest by ring key among entries [0, end).
  for (std::size_t qi = 30; qi < queries.size(); ++qi) {
    const PlaceDescriptor3D& q = queries[qi];
    std::vector<std::pair<double, std::size_t>> by_key;
    for (std::size_t i = 0; i < end; ++i) {
      double d = 0;
      for (std::size_t k = 0; k < q.ring_key.size(); ++k)
        d += std::pow(q.ring_key[k] - entries[i].ring_key[k], 2);
      by_key.emplace_back(d, i);
    }
    std::sort(by_key.begin(), by_key.end());
    const std::vector<PlaceCandidate> found = database.query(q, exclude, 10);
    ASSERT_EQ(found.size(), 10u);
    std::set<std::size_t> expected, got;
    for (std::size_t i = 0; i < 10; ++i) {
      expected.insert(by_key[i].second);
      got.insert(found[i].index);
      EXPECT_DOUBLE_EQ(found[i].distance, compare(q, entries[found[i].index]).distance);
    }
    EXPECT_EQ(got, expected);
  }
  // A database whose newest entries are near copies of the query: excluded, they never come back.
  PlaceDatabase3D with_copies(options);
  for (std::size_t i = 0; i < 120; ++i) with_copies.add(entries[i]);
  for (int i = 0; i < 8; ++i) with_copies.add(queries[0]);
  for (const PlaceCandidate& c : with_copies.query(queries[0], 8, 10)) EXPECT_LT(c.index, 120u);
  EXPECT_GE(with_copies.query(queries[0], 7, 10).at(0).index, 120u);

  // Query time against comparing with every entry (printed, not asserted: shared machines).
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  std::size_t sink = 0;
  for (std::size_t qi = 0; qi < 30; ++qi) sink += database.query(queries[qi], 0, 10).size();
  const auto t1 = Clock::now();
  for (std::size_t qi = 0; qi < 30; ++qi) {
    std::vector<std::pair<double, std::size_t>> all;
    for (std::size_t i = 0; i < entries.size(); ++i)
      all.emplace_back(compare(queries[qi], entries[i]).distance, i);
    std::partial_sort(all.begin(), all.begin() + 10, all.end());
    sink += all[0].second;
  }
  const auto t2 = Clock::now();
  const double tree_ms = std::chrono::duration<double, std::milli>(t1 - t0).count() / 30;
  const double brute_ms = std::chrono::duration<double, std::milli>(t2 - t1).count() / 30;
  std::printf("[ place ] %zu descriptors: query %.3f ms, brute force %.2f ms (%.0fx) [%zu]\n",
              entries.size(), tree_ms, brute_ms, brute_ms / tree_ms, sink % 2);
}
