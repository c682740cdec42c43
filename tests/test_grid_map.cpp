// Occupancy grid mapping: ray tracing against hand-computed cells, a simulated room against its
// true walls, growth, and the PGM / YAML / PNG files read back byte by byte.

#include <gtest/gtest.h>
#include <zlib.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <utility>

#include "scanmatch/core/error.hpp"
#include "scanmatch/io/image.hpp"
#include "scanmatch/mapping2d/grid_map.hpp"
#include "test_helpers.hpp"

using namespace scanmatch;
using scanmatch::testing::TempDir;

namespace {

double sigmoid(double log_odds) {
  return 1.0 / (1.0 + std::exp(-log_odds));
}

// Log-odds are stored as float.
constexpr double kProbabilityTolerance = 1e-6;

Eigen::Isometry2d pose(double x, double y, double theta) {
  Eigen::Isometry2d T = Eigen::Isometry2d::Identity();
  T.translate(Eigen::Vector2d(x, y));
  T.rotate(theta);
  return T;
}

GridMapOptions with_resolution(double resolution) {
  GridMapOptions options;
  options.resolution = resolution;
  return options;
}

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

// An axis-aligned rectangular room; beams from inside hit its walls.
struct Room {
  Eigen::Vector2d low, high;

  // Distance from `origin` (inside) along unit `direction` to the first wall.
  double range(const Eigen::Vector2d& origin, const Eigen::Vector2d& direction) const {
    double best = std::numeric_limits<double>::infinity();
    for (int axis = 0; axis < 2; ++axis) {
      if (direction[axis] > 0) best = std::min(best, (high[axis] - origin[axis]) / direction[axis]);
      if (direction[axis] < 0) best = std::min(best, (low[axis] - origin[axis]) / direction[axis]);
    }
    return best;
  }

  // Distance from `p` to the nearest wall (inside or outside the room).
  double distance_to_walls(const Eigen::Vector2d& p) const {
    const bool inside = (p.array() >= low.array()).all() && (p.array() <= high.array()).all();
    if (inside)
      return std::min({p.x() - low.x(), high.x() - p.x(), p.y() - low.y(), high.y() - p.y()});
    const Eigen::Vector2d outside = (low - p).cwiseMax(p - high).cwiseMax(Eigen::Vector2d::Zero());
    return outside.norm();
  }

  double perimeter() const { return 2 * ((high - low).x() + (high - low).y()); }

  // Points along the walls every `spacing` metres.
  std::vector<Eigen::Vector2d> wall_samples(double spacing) const {
    const Eigen::Vector2d corners[4] = {low, {high.x(), low.y()}, high, {low.x(), high.y()}};
    std::vector<Eigen::Vector2d> samples;
    for (int i = 0; i < 4; ++i) {
      const Eigen::Vector2d a = corners[i], b = corners[(i + 1) % 4];
      const int n = static_cast<int>(std::ceil((b - a).norm() / spacing));
      for (int k = 0; k < n; ++k) samples.push_back(a + (b - a) * (k / static_cast<double>(n)));
    }
    return samples;
  }
};

// A 4 m x 3 m room whose walls do not fall on cell boundaries of a 5 cm grid.
const Room kRoom{{-1.013, -0.987}, {2.987, 2.013}};

// 360 beams, one per degree, in the sensor frame.
std::vector<Eigen::Vector2d> simulate_scan(const Room& room, const Eigen::Isometry2d& sensor) {
  std::vector<Eigen::Vector2d> hits;
  for (int beam = 0; beam < 360; ++beam) {
    const double angle = beam * M_PI / 180.0;
    const Eigen::Vector2d local(std::cos(angle), std::sin(angle));
    const double range = room.range(sensor.translation(), sensor.linear() * local);
    hits.push_back(range * local);
  }
  return hits;
}

// Every cell of the grid: centre and probability.
std::vector<std::pair<Eigen::Vector2d, double>> snapshot(const OccupancyGrid& grid) {
  std::vector<std::pair<Eigen::Vector2d, double>> cells;
  for (int row = 0; row < grid.height(); ++row)
    for (int column = 0; column < grid.width(); ++column) {
      const Eigen::Vector2d centre = grid.cell_centre(column, row);
      cells.emplace_back(centre, grid.probability(centre));
    }
  return cells;
}

int observed_cell_count(const OccupancyGrid& grid) {
  int count = 0;
  for (const auto& [centre, p] : snapshot(grid)) count += grid.observed(centre) ? 1 : 0;
  return count;
}

struct Pgm {
  int width = 0, height = 0, maxval = 0;
  std::vector<std::uint8_t> pixels;
};

// Parsed here, not by the library's read_pgm: the writer is checked by an independent reader.
Pgm parse_pgm(const std::string& path) {
  const std::string bytes = read_bytes(path);
  Pgm pgm;
  std::istringstream header(bytes);
  std::string magic;
  header >> magic >> pgm.width >> pgm.height >> pgm.maxval;
  EXPECT_EQ(magic, "P5");
  // Exactly one whitespace byte separates maxval from the pixels.
  const std::size_t start = static_cast<std::size_t>(header.tellg()) + 1;
  pgm.pixels.assign(bytes.begin() + static_cast<std::ptrdiff_t>(start), bytes.end());
  return pgm;
}

std::uint32_t read_u32_be(const std::string& bytes, std::size_t at) {
  return (std::uint32_t{static_cast<unsigned char>(bytes[at])} << 24) |
         (std::uint32_t{static_cast<unsigned char>(bytes[at + 1])} << 16) |
         (std::uint32_t{static_cast<unsigned char>(bytes[at + 2])} << 8) |
         std::uint32_t{static_cast<unsigned char>(bytes[at + 3])};
}

struct Png {
  std::uint32_t width = 0, height = 0;
  int bit_depth = 0, colour_type = 0, interlace = 0;
  int idat_chunks = 0;
  std::vector<std::uint8_t> pixels;  // without the per-row filter bytes
};

// A minimal PNG reader for what write_png produces: checks the signature, the chunk order and
// every CRC, inflates the concatenated IDAT data and checks that each row uses filter 0.
Png read_png(const std::string& path, int channels) {
  const std::string bytes = read_bytes(path);
  Png png;
  EXPECT_GE(bytes.size(), 8u);
  EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  std::string compressed;
  std::vector<std::string> types;
  std::size_t at = 8;
  while (at + 12 <= bytes.size()) {
    const std::uint32_t length = read_u32_be(bytes, at);
    const std::string type = bytes.substr(at + 4, 4);
    const std::string data = bytes.substr(at + 8, length);
    const uLong crc = crc32(crc32(0L, Z_NULL, 0),
                            reinterpret_cast<const Bytef*>(bytes.data() + at + 4), 4 + length);
    EXPECT_EQ(read_u32_be(bytes, at + 8 + length), static_cast<std::uint32_t>(crc)) << type;
    types.push_back(type);
    if (type == "IHDR") {
      png.width = read_u32_be(data, 0);
      png.height = read_u32_be(data, 4);
      png.bit_depth = static_cast<unsigned char>(data[8]);
      png.colour_type = static_cast<unsigned char>(data[9]);
      png.interlace = static_cast<unsigned char>(data[12]);
    } else if (type == "IDAT") {
      compressed += data;
      ++png.idat_chunks;
    }
    at += 12 + length;
  }
  EXPECT_EQ(at, bytes.size());
  EXPECT_GE(types.size(), 3u);
  if (types.size() < 3) return png;
  EXPECT_EQ(types.front(), "IHDR");
  EXPECT_EQ(types.back(), "IEND");

  const std::size_t row_bytes = png.width * static_cast<std::size_t>(channels);
  std::vector<Bytef> raw(png.height * (row_bytes + 1));
  uLongf raw_size = raw.size();
  EXPECT_EQ(uncompress(raw.data(), &raw_size, reinterpret_cast<const Bytef*>(compressed.data()),
                       compressed.size()),
            Z_OK);
  EXPECT_EQ(raw_size, raw.size());
  for (std::size_t row = 0; row < png.height; ++row) {
    EXPECT_EQ(raw[row * (row_bytes + 1)], 0) << "filter byte of row " << row;
    const auto begin = raw.begin() + static_cast<std::ptrdiff_t>(row * (row_bytes + 1) + 1);
    png.pixels.insert(png.pixels.end(), begin, begin + static_cast<std::ptrdiff_t>(row_bytes));
  }
  return png;
}

template <class F>
std::string error_message(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no Error thrown)";
}

}  // namespace

TEST(GridMap, SingleRayMarksFreeCellsThenTheHitCell) {
  OccupancyGrid grid(with_resolution(0.1));
  EXPECT_EQ(grid.width(), 0);
  EXPECT_DOUBLE_EQ(grid.probability({0.0, 0.0}), 0.5);

  // Sensor in cell (0, 0), hit in cell (10, 0).
  grid.insert_scan(pose(0.05, 0.05, 0.0), {{1.0, 0.0}});
  for (int i = 0; i < 10; ++i) {
    const Eigen::Vector2d centre(0.1 * i + 0.05, 0.05);
    EXPECT_NEAR(grid.probability(centre), sigmoid(-0.4), kProbabilityTolerance) << i;
    EXPECT_FALSE(grid.occupied(centre)) << i;
  }
  EXPECT_NEAR(grid.probability({1.05, 0.05}), sigmoid(0.85), kProbabilityTolerance);
  EXPECT_TRUE(grid.occupied({1.05, 0.05}));
  EXPECT_EQ(grid.state({1.05, 0.05}), CellState::kOccupied);

  // Beyond the hit and beside the ray: never observed.
  for (const Eigen::Vector2d& p :
       {Eigen::Vector2d(1.15, 0.05), Eigen::Vector2d(1.55, 0.05), Eigen::Vector2d(0.55, 0.15),
        Eigen::Vector2d(0.55, -0.05), Eigen::Vector2d(-0.05, 0.05), Eigen::Vector2d(50.0, 50.0)}) {
    EXPECT_FALSE(grid.observed(p)) << p.transpose();
    EXPECT_DOUBLE_EQ(grid.probability(p), 0.5) << p.transpose();
    EXPECT_EQ(grid.state(p), CellState::kUnknown);
  }
  EXPECT_EQ(observed_cell_count(grid), 11);
  const std::vector<Eigen::Vector2d> occupied = grid.occupied_cell_centres();
  ASSERT_EQ(occupied.size(), 1u);
  EXPECT_NEAR(occupied[0].x(), 1.05, 1e-12);
  EXPECT_NEAR(occupied[0].y(), 0.05, 1e-12);
}

TEST(GridMap, RepeatedScansReachTheThresholdsAndTheClamps) {
  OccupancyGrid grid(with_resolution(0.1));
  const Eigen::Vector2d before(0.55, 0.05), end(1.05, 0.05);
  // One miss gives p = 0.40; free (< 0.196) needs four: 3 x -0.4 -> 0.23, 4 x -0.4 -> 0.17.
  for (int scan = 1; scan <= 4; ++scan) {
    grid.insert_scan(pose(0.05, 0.05, 0.0), {{1.0, 0.0}});
    EXPECT_EQ(grid.state(before), scan < 4 ? CellState::kUnknown : CellState::kFree) << scan;
    EXPECT_NEAR(grid.probability(before), sigmoid(-0.4 * scan), kProbabilityTolerance);
    EXPECT_NEAR(grid.probability(end), sigmoid(0.85 * scan), kProbabilityTolerance);
  }
  for (int scan = 0; scan < 10; ++scan) grid.insert_scan(pose(0.05, 0.05, 0.0), {{1.0, 0.0}});
  EXPECT_NEAR(grid.probability(before), sigmoid(-2.0), kProbabilityTolerance);
  EXPECT_NEAR(grid.probability(end), sigmoid(3.5), kProbabilityTolerance);
  // Clamped, so one opposite observation moves the cell at once.
  grid.insert_scan(pose(0.05, 0.05, 0.0), {{0.5, 0.0}});
  EXPECT_NEAR(grid.probability(before), sigmoid(-2.0 + 0.85), kProbabilityTolerance);
}

TEST(GridMap, PoseRotatesAndTranslatesTheBeams) {
  OccupancyGrid grid(with_resolution(0.1));
  // Facing +y: a return 0.52 m ahead lands at (1.03, 2.56).
  grid.insert_scan(pose(1.03, 2.04, M_PI / 2), {{0.52, 0.0}});
  EXPECT_TRUE(grid.occupied({1.03, 2.56}));
  EXPECT_NEAR(grid.probability({1.03, 2.34}), sigmoid(-0.4), kProbabilityTolerance);
  EXPECT_FALSE(grid.observed({1.03, 2.75}));
  EXPECT_FALSE(grid.observed({1.55, 2.34}));
  EXPECT_EQ(observed_cell_count(grid), 6);  // y cells 20..25
}

TEST(GridMap, SlantedRaysVisitExactlyTheCellsTheSegmentCrosses) {
  const double resolution = 0.1;
  const Eigen::Vector2d sensor(0.03, 0.07);
  for (const Eigen::Vector2d& end :
       {Eigen::Vector2d(1.234, 0.871), Eigen::Vector2d(-0.913, -1.327),
        Eigen::Vector2d(-0.611, 0.4567), Eigen::Vector2d(0.0712, -1.93)}) {
    OccupancyGrid grid(with_resolution(resolution));
    grid.insert_scan(pose(sensor.x(), sensor.y(), 0.0), {end - sensor});

    // Brute force: the cells under a dense sampling of the segment.
    std::set<std::pair<int, int>> crossed;
    for (int k = 0; k <= 200000; ++k) {
      const Eigen::Vector2d p = sensor + (end - sensor) * (k / 200000.0);
      crossed.emplace(static_cast<int>(std::floor(p.x() / resolution)),
                      static_cast<int>(std::floor(p.y() / resolution)));
    }
    const auto centre = [&](const std::pair<int, int>& cell) {
      return Eigen::Vector2d((cell.first + 0.5) * resolution, (cell.second + 0.5) * resolution);
    };
    const std::pair<int, int> end_cell(static_cast<int>(std::floor(end.x() / resolution)),
                                       static_cast<int>(std::floor(end.y() / resolution)));
    for (const auto& cell : crossed) {
      const double expected = cell == end_cell ? sigmoid(0.85) : sigmoid(-0.4);
      EXPECT_NEAR(grid.probability(centre(cell)), expected, kProbabilityTolerance)
          << "cell " << cell.first << ", " << cell.second << " of the ray to " << end.transpose();
    }
    EXPECT_EQ(observed_cell_count(grid), static_cast<int>(crossed.size())) << end.transpose();
  }
}

TEST(GridMap, MissesOnlyFreeCellsUpToTheirEndPoint) {
  OccupancyGrid grid(with_resolution(0.1));
  grid.insert_scan(pose(0.05, 0.05, 0.0), {}, {{0.5, 0.0}});
  for (int i = 0; i <= 5; ++i)
    EXPECT_NEAR(grid.probability({0.1 * i + 0.05, 0.05}), sigmoid(-0.4), kProbabilityTolerance);
  EXPECT_FALSE(grid.observed({0.65, 0.05}));
  EXPECT_TRUE(grid.occupied_cell_centres().empty());
}

TEST(GridMap, WithinOneScanEachCellIsUpdatedOnceAndHitsWin) {
  OccupancyGrid grid(with_resolution(0.1));
  // The second beam runs through the first one's hit cell; a max-range beam runs along both.
  grid.insert_scan(pose(0.05, 0.05, 0.0), {{1.0, 0.0}, {2.0, 0.0}}, {{3.0, 0.0}});
  EXPECT_NEAR(grid.probability({1.05, 0.05}), sigmoid(0.85), kProbabilityTolerance);
  EXPECT_NEAR(grid.probability({2.05, 0.05}), sigmoid(0.85), kProbabilityTolerance);
  EXPECT_NEAR(grid.probability({0.55, 0.05}), sigmoid(-0.4), kProbabilityTolerance);
  EXPECT_NEAR(grid.probability({1.55, 0.05}), sigmoid(-0.4), kProbabilityTolerance);
  EXPECT_NEAR(grid.probability({2.55, 0.05}), sigmoid(-0.4), kProbabilityTolerance);
}

TEST(GridMap, NonFiniteInputsAreSkipped) {
  OccupancyGrid grid(with_resolution(0.1));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  grid.insert_scan(pose(0.05, 0.05, 0.0), {{nan, 0.0}, {1.0, 0.0}, {inf, 1.0}}, {{0.0, -inf}});
  EXPECT_EQ(observed_cell_count(grid), 11);
  EXPECT_TRUE(grid.occupied({1.05, 0.05}));
  grid.insert_scan(pose(nan, 0.0, 0.0), {{1.0, 0.0}});
  grid.insert_scan(pose(0.0, 0.0, nan), {{1.0, 0.0}});
  EXPECT_EQ(observed_cell_count(grid), 11);
}

TEST(GridMap, SimulatedRoomGivesOccupiedCellsOnTheWalls) {
  const GridMapOptions options;  // 5 cm cells
  OccupancyGrid grid(options);
  const Eigen::Isometry2d sensor = pose(0.31, 0.42, 0.3);
  grid.insert_scan(sensor, simulate_scan(kRoom, sensor));

  const std::vector<Eigen::Vector2d> occupied = grid.occupied_cell_centres();
  ASSERT_FALSE(occupied.empty());
  for (const Eigen::Vector2d& c : occupied)
    EXPECT_LE(kRoom.distance_to_walls(c), options.resolution) << c.transpose();

  // Coverage: the share of wall points with an occupied cell within one cell. Beams are 1 degree
  // apart, at most 3.5 m from the walls, so gaps appear only where beams graze a wall near a
  // far corner.
  const std::vector<Eigen::Vector2d> samples = kRoom.wall_samples(0.01);
  int covered = 0;
  for (const Eigen::Vector2d& s : samples) {
    for (const Eigen::Vector2d& c : occupied)
      if ((c - s).lpNorm<Eigen::Infinity>() <= options.resolution) {
        ++covered;
        break;
      }
  }
  EXPECT_GT(covered, 0.95 * samples.size()) << covered << " of " << samples.size();
  // Each beam marks one cell, about 360 cells against 280 cells of perimeter.
  EXPECT_GT(occupied.size(), 0.85 * kRoom.perimeter() / options.resolution);
  EXPECT_LE(occupied.size(), 360u);

  // The sensor's surroundings were observed free, beyond the walls nothing was observed.
  EXPECT_NEAR(grid.probability(sensor.translation()), sigmoid(-0.4), kProbabilityTolerance);
  EXPECT_FALSE(grid.observed({kRoom.high.x() + 0.3, 0.5}));
  EXPECT_FALSE(grid.observed({0.5, kRoom.low.y() - 0.3}));
  // The grid holds the whole room (a margin included).
  EXPECT_GE(grid.width() * options.resolution, 4.0);
  EXPECT_GE(grid.height() * options.resolution, 3.0);
}

// insert_scan against a straightforward version of it: each beam's cells from a grid holding
// that beam alone, their union per scan (hits winning), one clamped update per cell, in float.
// Many beams of a scan cross near the sensor, scans overlap and repeat (the clamps), and the grid
// grows and is cropped between them.
TEST(GridMap, InsertScanMatchesOneUpdatePerCellOfTheBeamsUnion) {
  const GridMapOptions options = with_resolution(0.1);
  using Cell = std::pair<long, long>;
  const auto cell_of = [&](const Eigen::Vector2d& world) {
    return Cell(static_cast<long>(std::floor(world.x() / options.resolution)),
                static_cast<long>(std::floor(world.y() / options.resolution)));
  };
  const auto centre = [&](const Cell& c) {
    return Eigen::Vector2d((c.first + 0.5) * options.resolution,
                           (c.second + 0.5) * options.resolution);
  };
  // One beam alone: its observed cells are the ray's, the occupied one its end.
  const auto beam_cells = [&](const Eigen::Isometry2d& at, const Eigen::Vector2d& end, bool hit,
                              std::set<Cell>& free, std::set<Cell>& hits) {
    OccupancyGrid alone(options);
    if (hit)
      alone.insert_scan(at, {end});
    else
      alone.insert_scan(at, {}, {end});
    for (int row = 0; row < alone.height(); ++row)
      for (int column = 0; column < alone.width(); ++column) {
        const Eigen::Vector2d c = alone.cell_centre(column, row);
        if (!alone.observed(c)) continue;
        (alone.occupied(c) ? hits : free).insert(cell_of(c));
      }
  };
  std::map<Cell, float> expected;
  OccupancyGrid grid(options);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int scan = 0; scan < 24; ++scan) {
    // Back and forth between two places 6 m apart, so that later scans grow the grid.
    const Eigen::Isometry2d at = pose(scan % 3 == 2 ? 6.0 + unit(random) : unit(random),
                                      unit(random), 2 * M_PI * unit(random));
    std::vector<Eigen::Vector2d> hits, misses;
    for (int beam = 0; beam < 60; ++beam) {
      const double angle = 2 * M_PI * beam / 60.0, range = 0.3 + 2.5 * unit(random);
      (beam % 7 == 0 ? misses : hits)
          .emplace_back(range * std::cos(angle), range * std::sin(angle));
    }
    grid.insert_scan(at, hits, misses);
    std::set<Cell> free_cells, hit_cells;
    for (const Eigen::Vector2d& h : hits) beam_cells(at, h, true, free_cells, hit_cells);
    for (const Eigen::Vector2d& m : misses) beam_cells(at, m, false, free_cells, free_cells);
    const auto update = [&](const Cell& c, double delta) {
      const auto it = expected.find(c);
      const double before = it == expected.end() ? 0.0 : it->second;
      expected[c] = static_cast<float>(
          std::clamp(before + delta, options.min_log_odds, options.max_log_odds));
    };
    for (const Cell& c : free_cells)
      if (!hit_cells.count(c)) update(c, options.miss_log_odds);
    for (const Cell& c : hit_cells) update(c, options.hit_log_odds);
    if (scan == 10) grid.crop_to_observed();
  }
  EXPECT_EQ(observed_cell_count(grid), static_cast<int>(expected.size()));
  for (const auto& [cell, log_odds] : expected)
    ASSERT_EQ(grid.probability(centre(cell)), log_odds_to_probability(log_odds))
        << "cell " << cell.first << ", " << cell.second;
}

TEST(GridMap, GrowingKeepsCellsAtTheirWorldPositions) {
  OccupancyGrid grid(with_resolution(0.1));
  grid.insert_scan(pose(0.05, 0.05, 0.3), {{1.0, 0.2}, {-0.7, 0.4}}, {{0.3, -1.1}});
  const auto before = snapshot(grid);
  const std::vector<Eigen::Vector2d> occupied_before = grid.occupied_cell_centres();
  const Eigen::Vector2d origin_before = grid.origin();
  const int width_before = grid.width(), height_before = grid.height();

  // Far below-left and far above-right of the current grid.
  grid.insert_scan(pose(-30.0, -20.0, 0.0), {{1.03, 0.02}});
  grid.insert_scan(pose(40.0, 25.0, 0.0), {{0.02, 1.03}});
  EXPECT_LT(grid.origin().x(), origin_before.x());
  EXPECT_LT(grid.origin().y(), origin_before.y());
  EXPECT_GT(grid.width(), width_before);
  EXPECT_GT(grid.height(), height_before);
  EXPECT_LE(grid.origin().x(), -30.0);
  EXPECT_GE(grid.origin().x() + grid.width() * 0.1, 40.02);
  EXPECT_GE(grid.origin().y() + grid.height() * 0.1, 26.03);
  // The origin stays on the cell lattice.
  EXPECT_NEAR(grid.origin().x() / 0.1, std::round(grid.origin().x() / 0.1), 1e-9);

  for (const auto& [centre, p] : before)
    EXPECT_DOUBLE_EQ(grid.probability(centre), p) << centre.transpose();
  EXPECT_TRUE(grid.occupied({-28.97, -19.98}));
  EXPECT_TRUE(grid.occupied({40.02, 26.03}));
  const std::vector<Eigen::Vector2d> occupied_after = grid.occupied_cell_centres();
  EXPECT_EQ(occupied_after.size(), occupied_before.size() + 2);
  for (const Eigen::Vector2d& c : occupied_before) {
    bool found = false;
    for (const Eigen::Vector2d& d : occupied_after) found = found || (c - d).norm() < 1e-9;
    EXPECT_TRUE(found) << c.transpose();
  }
}

TEST(GridMap, RefusesToGrowBeyondTheCellLimit) {
  OccupancyGrid grid;  // 5 cm
  grid.insert_scan(pose(0.0, 0.0, 0.0), {{1.0, 0.0}});
  const auto before = snapshot(grid);
  const int width = grid.width(), height = grid.height();
  // 1 km x 1 km at 5 cm is 400 million cells.
  EXPECT_THROW(grid.insert_scan(pose(0.0, 0.0, 0.0), {{1000.0, 1000.0}}), Error);
  // Beyond the range of 32-bit cell indices.
  EXPECT_THROW(grid.insert_scan(pose(0.0, 0.0, 0.0), {{1e12, 0.0}}), Error);
  EXPECT_THROW(grid.insert_scan(pose(1e300, 0.0, 0.0), {{1.0, 0.0}}), Error);
  // Unchanged by the failed insertions.
  EXPECT_EQ(grid.width(), width);
  EXPECT_EQ(grid.height(), height);
  for (const auto& [centre, p] : before) EXPECT_DOUBLE_EQ(grid.probability(centre), p);
  // A long but thin ray is fine: 2 km x 1 cell plus margins.
  OccupancyGrid corridor;
  EXPECT_NO_THROW(corridor.insert_scan(pose(0.0, 0.0, 0.0), {{2000.0, 0.0}}));
  EXPECT_TRUE(corridor.occupied({2000.0, 0.0}));
}

TEST(GridMap, NearTheCellLimitItStillGrowsAheadOfTheScans) {
  // A robot driving 22 m along a corridor, a scan every 10 cm, its map capped at 50 000 cells of 10
  // cm (a large outdoor log's 100 million at 5 cm, scaled down): growing only to each scan's extent
  // near the cap copied the whole grid at most scans; grown by what still fits, it is copied a few
  // times, and holds the same cells.
  GridMapOptions capped = with_resolution(0.1);
  capped.max_cells = 50'000;
  OccupancyGrid grid(capped), unlimited(with_resolution(0.1));
  int growths = 0;
  for (int step = 0; step <= 220; ++step) {
    const Eigen::Isometry2d at = pose(0.1 * step, 0.0, 0.0);
    const std::vector<Eigen::Vector2d> walls = {{2.0, 1.2}, {2.0, -1.2}, {-1.0, 1.2}, {3.0, 0.0}};
    const int width = grid.width(), height = grid.height();
    const Eigen::Vector2d origin = grid.origin();
    grid.insert_scan(at, walls);
    unlimited.insert_scan(at, walls);
    growths += grid.width() != width || grid.height() != height || grid.origin() != origin;
  }
  std::printf("growths of the capped grid: %d, %d x %d cells\n", growths, grid.width(),
              grid.height());
  EXPECT_LE(static_cast<std::size_t>(grid.width()) * static_cast<std::size_t>(grid.height()),
            capped.max_cells);
  EXPECT_LE(growths, 10);
  for (int step = 0; step <= 60; ++step)
    for (const Eigen::Vector2d& q :
         {Eigen::Vector2d(0.5 * step + 2.0, 1.2), Eigen::Vector2d(0.5 * step + 1.0, 0.05),
          Eigen::Vector2d(0.5 * step, -0.6)})
      EXPECT_EQ(grid.probability(q), unlimited.probability(q)) << q.transpose();
  EXPECT_TRUE(grid.occupied({24.0, 1.2}));
  GridMapOptions none = with_resolution(0.1);
  none.max_cells = 0;
  EXPECT_THROW(OccupancyGrid{none}, Error);
}

TEST(GridMap, RejectsInconsistentOptions) {
  const auto with = [](auto change) {
    GridMapOptions options;
    change(options);
    return options;
  };
  EXPECT_THROW(OccupancyGrid(with([](GridMapOptions& o) { o.resolution = 0; })), Error);
  EXPECT_THROW(OccupancyGrid(with([](GridMapOptions& o) { o.resolution = -0.1; })), Error);
  EXPECT_THROW(OccupancyGrid(with([](GridMapOptions& o) { o.hit_log_odds = -1; })), Error);
  EXPECT_THROW(OccupancyGrid(with([](GridMapOptions& o) { o.miss_log_odds = 0.4; })), Error);
  EXPECT_THROW(OccupancyGrid(with([](GridMapOptions& o) { o.max_log_odds = -1; })), Error);
  EXPECT_THROW(OccupancyGrid(with([](GridMapOptions& o) { o.free_threshold = 0.7; })), Error);
  EXPECT_THROW(OccupancyGrid(with([](GridMapOptions& o) { o.occupied_threshold = 1.0; })), Error);
}

TEST(GridMap, MapServerFilesReadBack) {
  TempDir dir;
  const GridMapOptions options;
  OccupancyGrid grid(options);
  const Eigen::Isometry2d sensor = pose(0.31, 0.42, 0.3);
  // Four identical scans: enough misses for the free threshold.
  for (int i = 0; i < 4; ++i) grid.insert_scan(sensor, simulate_scan(kRoom, sensor));

  grid.write_map_server(dir.file("room.pgm"));
  ASSERT_TRUE(std::filesystem::exists(dir.file("room.yaml")));

  // YAML: exact lines, and the origin the image is placed by.
  std::ifstream yaml(dir.file("room.yaml"));
  std::vector<std::string> lines;
  for (std::string line; std::getline(yaml, line);) lines.push_back(line);
  ASSERT_EQ(lines.size(), 7u);
  EXPECT_EQ(lines[0], "image: room.pgm");
  EXPECT_EQ(lines[1], "resolution: 0.05");
  double ox = 0, oy = 0, oyaw = 1;
  ASSERT_EQ(std::sscanf(lines[2].c_str(), "origin: [%lf, %lf, %lf]", &ox, &oy, &oyaw), 3)
      << lines[2];
  EXPECT_DOUBLE_EQ(ox, grid.origin().x());
  EXPECT_DOUBLE_EQ(oy, grid.origin().y());
  EXPECT_EQ(oyaw, 0.0);
  EXPECT_EQ(lines[3], "negate: 0");
  EXPECT_EQ(lines[4], "occupied_thresh: 0.65");
  EXPECT_EQ(lines[5], "free_thresh: 0.196");
  EXPECT_EQ(lines[6], "mode: trinary");

  // PGM: header, size, and every pixel against the grid (row 0 = highest y).
  const Pgm pgm = parse_pgm(dir.file("room.pgm"));
  ASSERT_EQ(pgm.width, grid.width());
  ASSERT_EQ(pgm.height, grid.height());
  EXPECT_EQ(pgm.maxval, 255);
  ASSERT_EQ(pgm.pixels.size(), static_cast<std::size_t>(pgm.width) * pgm.height);
  EXPECT_EQ(pgm.pixels, grid.render());
  int counts[3] = {0, 0, 0};
  for (int row = 0; row < pgm.height; ++row)
    for (int column = 0; column < pgm.width; ++column) {
      const CellState state = grid.state(grid.cell_centre(column, pgm.height - 1 - row));
      const std::uint8_t expected = state == CellState::kOccupied ? 0
                                    : state == CellState::kFree   ? 254
                                                                  : 205;
      ASSERT_EQ(pgm.pixels[static_cast<std::size_t>(row) * pgm.width + column], expected)
          << "row " << row << " column " << column;
      ++counts[expected == 0 ? 0 : expected == 254 ? 1 : 2];
    }
  EXPECT_GT(counts[0], 250);
  EXPECT_GT(counts[1], 0.8 * 12.0 / (0.05 * 0.05));  // most of the 12 m^2 room
  EXPECT_GT(counts[2], 0);

  // Locating world points through the YAML alone, as map_server does.
  const auto pixel_at = [&](const Eigen::Vector2d& world) {
    const int column = static_cast<int>(std::floor((world.x() - ox) / 0.05));
    const int row = pgm.height - 1 - static_cast<int>(std::floor((world.y() - oy) / 0.05));
    return pgm.pixels[static_cast<std::size_t>(row) * pgm.width + column];
  };
  EXPECT_EQ(pixel_at(sensor.translation()), 254);
  EXPECT_EQ(pixel_at({2.5, 1.8}), 254);                   // near the top-right corner, inside
  EXPECT_EQ(pixel_at({kRoom.high.x() + 0.5, 1.0}), 205);  // beyond a wall
  for (const Eigen::Vector2d& c : grid.occupied_cell_centres()) ASSERT_EQ(pixel_at(c), 0);

  // The same files from a base name, and from the YAML name.
  grid.write_map_server(dir.file("base"));
  EXPECT_EQ(read_bytes(dir.file("base.pgm")), read_bytes(dir.file("room.pgm")));
  EXPECT_NE(read_bytes(dir.file("base.yaml")).find("image: base.pgm\n"), std::string::npos);
  grid.write_map_server(dir.file("other.yaml"));
  EXPECT_TRUE(std::filesystem::exists(dir.file("other.pgm")));
  // A name that YAML needs quoted.
  grid.write_map_server(dir.file("my map: 1"));
  EXPECT_NE(read_bytes(dir.file("my map: 1.yaml")).find("image: \"my map: 1.pgm\"\n"),
            std::string::npos);
  // Atomic writes leave no temporary files behind.
  for (const auto& entry : std::filesystem::directory_iterator(dir.path()))
    EXPECT_EQ(entry.path().string().find(".tmp."), std::string::npos) << entry.path();

  // PNG: the same pixels.
  grid.write_png(dir.file("room.png"));
  const Png png = read_png(dir.file("room.png"), 1);
  EXPECT_EQ(png.width, static_cast<std::uint32_t>(grid.width()));
  EXPECT_EQ(png.height, static_cast<std::uint32_t>(grid.height()));
  EXPECT_EQ(png.bit_depth, 8);
  EXPECT_EQ(png.colour_type, 0);
  EXPECT_EQ(png.interlace, 0);
  EXPECT_EQ(png.pixels, pgm.pixels);
}

TEST(GridMap, EmptyGridAndBadFoldersThrowNamingTheFile) {
  TempDir dir;
  OccupancyGrid grid;
  EXPECT_NE(error_message([&] { grid.write_map_server(dir.file("empty")); }).find("empty.pgm"),
            std::string::npos);
  EXPECT_NE(error_message([&] { grid.write_png(dir.file("empty.png")); }).find("empty.png"),
            std::string::npos);
  grid.insert_scan(pose(0.0, 0.0, 0.0), {{1.0, 0.0}});
  const std::string missing = dir.file("no/such/folder/map");
  EXPECT_NE(error_message([&] { grid.write_map_server(missing); }).find(missing + ".pgm"),
            std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(dir.file("empty.pgm")));
}

TEST(ImageIo, PgmBytesAreExact) {
  TempDir dir;
  const std::vector<std::uint8_t> pixels = {0, 1, 2, 253, 254, 255};
  write_pgm(dir.file("a.pgm"), 3, 2, pixels);
  EXPECT_EQ(read_bytes(dir.file("a.pgm")),
            std::string("P5\n3 2\n255\n") + std::string("\x00\x01\x02\xfd\xfe\xff", 6));
}

TEST(ImageIo, PngGreyAndRgbDecode) {
  TempDir dir;
  const std::vector<std::uint8_t> grey = {0, 50, 100, 150, 200, 250};
  write_png(dir.file("grey.png"), 2, 3, grey);
  const Png g = read_png(dir.file("grey.png"), 1);
  EXPECT_EQ(g.width, 2u);
  EXPECT_EQ(g.height, 3u);
  EXPECT_EQ(g.colour_type, 0);
  EXPECT_EQ(g.pixels, grey);

  const std::vector<std::uint8_t> rgb = {255, 0, 0, 0, 255, 0, 0, 0, 255, 10, 20, 30};
  write_png_rgb(dir.file("rgb.png"), 2, 2, rgb);
  const Png c = read_png(dir.file("rgb.png"), 3);
  EXPECT_EQ(c.width, 2u);
  EXPECT_EQ(c.height, 2u);
  EXPECT_EQ(c.bit_depth, 8);
  EXPECT_EQ(c.colour_type, 2);
  EXPECT_EQ(c.pixels, rgb);
}

TEST(ImageIo, LargeIncompressiblePngSpansSeveralDataChunks) {
  TempDir dir;
  std::mt19937 rng(7);
  std::vector<std::uint8_t> noise(1500 * 1000);
  for (auto& v : noise) v = static_cast<std::uint8_t>(rng());
  write_png(dir.file("noise.png"), 1500, 1000, noise);
  const Png png = read_png(dir.file("noise.png"), 1);
  EXPECT_GE(png.idat_chunks, 2);
  EXPECT_EQ(png.pixels, noise);
}

TEST(ImageIo, BadSizesThrowNamingTheFile) {
  TempDir dir;
  const std::string path = dir.file("bad.png");
  const std::vector<std::uint8_t> six(6, 0);
  const auto names_file = [&](auto f) { return error_message(f).find(path) != std::string::npos; };
  EXPECT_TRUE(names_file([&] { write_png(path, 2, 2, six); }));
  EXPECT_TRUE(names_file([&] { write_png(path, 0, 6, six); }));
  EXPECT_TRUE(names_file([&] { write_png(path, -2, -3, six); }));
  EXPECT_TRUE(names_file([&] { write_png_rgb(path, 2, 3, six); }));
  EXPECT_TRUE(names_file([&] { write_pgm(path, 4, 2, six); }));
  EXPECT_TRUE(names_file([&] { write_pgm(path, 6, 0, six); }));
  EXPECT_THROW(write_pgm(path, 3, 3, six), Error);
  EXPECT_FALSE(std::filesystem::exists(path));
  const std::string missing = dir.file("missing/bad.pgm");
  EXPECT_NE(error_message([&] { write_pgm(missing, 3, 2, six); }).find(missing), std::string::npos);
}
