#pragma once
// 2D occupancy grid mapping: laser scans are ray-traced into log-odds cells, and the map is
// exported in ROS map_server format (PGM + YAML) or as a PNG.
//
// Cells lie on a fixed world lattice: cell (i, j) covers [i r, (i+1) r) x [j r, (j+1) r) for
// resolution r. The grid stores the rectangle of that lattice that scans have reached so far and
// grows when a ray leaves it, so a cell keeps its world position for the life of the grid.

#include <Eigen/Geometry>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace scanmatch {

struct GridMapOptions {
  /// Edge length of a square cell, in metres. Default 0.05 (5 cm).
  double resolution = 0.05;
  /// Most cells the grid may hold (width x height; 4 bytes each): 100 million, 400 MB.
  std::size_t max_cells = 100'000'000;
  /// Log-odds added to the cell a beam ends in; must be positive. Default 0.85 (one hit alone
  /// gives p = 0.70).
  double hit_log_odds = 0.85;
  /// Log-odds added to each cell a beam passes through; must be negative. Default -0.4 (one miss
  /// alone gives p = 0.40).
  double miss_log_odds = -0.4;
  /// Lower clamp of a cell's log-odds, so a cell that was free can still become occupied when
  /// the world changes; must be negative. Default -2.0 (p = 0.12).
  double min_log_odds = -2.0;
  /// Upper clamp of a cell's log-odds, for the same reason; must be positive. Default 3.5
  /// (p = 0.97).
  double max_log_odds = 3.5;
  /// Probability above which a cell is occupied (black in the image). Default 0.65, as ROS
  /// map_server's occupied_thresh.
  double occupied_threshold = 0.65;
  /// Probability below which a cell is free (white in the image). Default 0.196, as ROS
  /// map_server's free_thresh. Cells between the two thresholds, and cells never observed, are
  /// unknown (grey). With the default increments a cell needs one hit to be occupied but four
  /// misses to be free.
  double free_threshold = 0.196;
};

enum class CellState {
  kUnknown,   ///< never observed, or probability between the two thresholds
  kFree,      ///< probability below free_threshold
  kOccupied,  ///< probability above occupied_threshold
};

/// The probability a log-odds value stands for.
inline double log_odds_to_probability(double log_odds) {
  return 1.0 / (1.0 + std::exp(-log_odds));
}

/// Grey levels of the map_server "trinary" rendering.
inline constexpr std::uint8_t kOccupiedPixel = 0;
inline constexpr std::uint8_t kFreePixel = 254;
inline constexpr std::uint8_t kUnknownPixel = 205;

class OccupancyGrid {
 public:
  /// An empty grid (width and height 0). Throws Error when the options are inconsistent: a
  /// non-positive resolution or max_cells, increments or clamps of the wrong sign, or thresholds
  /// not satisfying 0 < free_threshold < occupied_threshold < 1.
  explicit OccupancyGrid(const GridMapOptions& options = {});

  /// Ray-traces one scan taken from `sensor_pose` (sensor frame to world frame). For each hit
  /// (a return, in the sensor frame, m) the cells from the sensor up to but excluding the hit's
  /// cell get miss_log_odds and the hit's cell gets hit_log_odds. Each miss (a beam without a
  /// return, given as the end point of its free stretch, e.g. at maximum range) only frees
  /// cells: every cell from the sensor to the end point inclusive gets miss_log_odds.
  /// Within one scan a cell is updated at most once, and a cell that any beam hit is not also
  /// freed by another beam (a grazing beam would otherwise erase the wall it runs along).
  /// Log-odds are clamped to [min_log_odds, max_log_odds]. Non-finite points are skipped, and
  /// the whole scan when the pose is non-finite. The grid grows to contain every ray; throws
  /// Error, leaving the grid unchanged, when it would exceed max_cells or a point lies too far
  /// from the origin for 32-bit cell indices.
  void insert_scan(const Eigen::Isometry2d& sensor_pose,
                   const std::vector<Eigen::Vector2d>& hits_in_sensor_frame,
                   const std::vector<Eigen::Vector2d>& misses_in_sensor_frame = {});

  /// Occupancy probability of the cell containing `world`; 0.5 for a cell never observed
  /// (including everything outside the grid).
  double probability(const Eigen::Vector2d& world) const;
  /// Whether the cell containing `world` has been updated by at least one scan.
  bool observed(const Eigen::Vector2d& world) const;
  /// Classification of the cell containing `world` by the two thresholds.
  CellState state(const Eigen::Vector2d& world) const;
  bool occupied(const Eigen::Vector2d& world) const { return state(world) == CellState::kOccupied; }

  int width() const { return width_; }                       ///< cells along x
  int height() const { return height_; }                     ///< cells along y
  double resolution() const { return options_.resolution; }  ///< m per cell
  const GridMapOptions& options() const { return options_; }
  /// World coordinates (m) of the lower-left corner of cell (0, 0), the map_server origin.
  Eigen::Vector2d origin() const { return origin_cell_.cast<double>() * options_.resolution; }
  /// World coordinates of the centre of cell (column, row); row 0 is the lowest y.
  Eigen::Vector2d cell_centre(int column, int row) const;

  /// Shrinks the storage to the observed cells plus `margin` cells on each side, keeping every
  /// cell at its world position, so that exported images hold the mapped area only (growth
  /// leaves wide unobserved margins). Does nothing to an empty grid.
  void crop_to_observed(int margin = 2);

  /// Centres of the occupied cells, row by row from the lowest y, each row by increasing x.
  std::vector<Eigen::Vector2d> occupied_cell_centres() const;

  /// The map as width x height grey levels, image row 0 at the top (highest y): occupied
  /// kOccupiedPixel, free kFreePixel, unknown kUnknownPixel. Empty for an empty grid.
  std::vector<std::uint8_t> render() const;

  /// Writes NAME.pgm (the rendering, binary P5) and NAME.yaml (image, resolution, origin,
  /// negate, thresholds, mode) for ROS map_server, where NAME is `pgm_or_base_path` without a
  /// trailing ".pgm" or ".yaml". Both files are written atomically, the image first. Throws Error
  /// naming the file when the grid is empty or writing fails.
  void write_map_server(const std::string& pgm_or_base_path) const;

  /// Writes the rendering as an 8-bit grayscale PNG, atomically. Throws Error naming the file
  /// when the grid is empty or writing fails.
  void write_png(const std::string& path) const;

 private:
  // Storage index of the cell containing `world`, or -1 outside the grid.
  std::int64_t index_of(const Eigen::Vector2d& world) const;
  // Grows the grid (with a margin) so that it contains the lattice cells [low, high].
  void ensure_contains(const Eigen::Vector2i& low, const Eigen::Vector2i& high);

  GridMapOptions options_;
  Eigen::Vector2i origin_cell_ = Eigen::Vector2i::Zero();  // lattice index of cell (0, 0)
  int width_ = 0;
  int height_ = 0;
  std::vector<float> log_odds_;  // row-major from the lowest y; NaN marks a cell never observed
  // insert_scan's per-cell marks of the scan being inserted, as log_odds_; zero between scans.
  std::vector<std::uint8_t> scan_marks_;
};

}  // namespace scanmatch
