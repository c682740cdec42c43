#pragma once
// Place recognition for loop closure, in the spirit of Scan Context (Kim & Kim 2018): a scan
// becomes a polar grid (rings of range x sectors of bearing) around the sensor. Turning the sensor
// on the spot shifts the grid's columns circularly, so two scans of one place compare by the best
// column shift, which is also the yaw between them. A rotation-invariant per-ring key lets the
// place database (place_database.hpp) find candidates before the full comparison.
//
// 3D cells hold the maximum height of their points; 2D cells hold how many of the sector's beams
// reach past the ring (a free-space profile that changes smoothly when the sensor moves a little,
// and that leaves sectors without beams empty, so 180-degree scans compare with 360-degree ones).

#include <cstddef>
#include <vector>

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/core/scan2d.hpp"

namespace scanmatch {

/// The polar grid both descriptors share. Sector j spans bearings [j, j + 1) * 2 pi / sectors,
/// counter-clockwise from the sensor's x axis; ring i spans ranges [i, i + 1) * max_range / rings.
struct PlaceDescriptor {
  int rings = 0, sectors = 0;
  std::vector<float> cells;       ///< rings x sectors, sector-major: cells[sector * rings + ring]
  std::vector<float> ring_key;    ///< per ring, rotation-invariant (see the make functions)
  std::vector<float> sector_key;  ///< per sector, the mean of its cells (for the yaw search)
  std::vector<bool> column_used;  ///< per sector: any points (3D) or beams (2D) fell in it
  bool empty() const { return cells.empty(); }
  /// Sectors with something in them.
  std::size_t used_columns() const;
};
/// Distinct types so 2D and 3D descriptors never meet in one comparison or database.
struct PlaceDescriptor3D : PlaceDescriptor {};
struct PlaceDescriptor2D : PlaceDescriptor {};

struct PlaceDescriptorOptions {  ///< 3D
  int rings = 20;
  int sectors = 60;
  double max_range = 80.0;  ///< m, horizontal range of the outer ring; farther points are ignored
  /// m added to z (sensor frame) so the ground is positive: the sensor's height above the ground
  /// is a good value. Points lower than -height_offset count as height 0.
  double height_offset = 2.0;
};

struct PlaceDescriptor2DOptions {
  int rings = 20;
  int sectors = 60;
  double max_range = 10.0;  ///< m, the outer ring (indoor lasers); beams beyond reach past it all
};

/// The descriptor of a 3D scan in its sensor frame (z up). Cell: max(z + height_offset, 0) of its
/// points, 0 when empty. Ring key: the fraction of the ring's sectors that hold points. NaN and
/// infinite points are skipped; no valid point gives an empty descriptor.
PlaceDescriptor3D make_place_descriptor(const PointCloud& cloud_in_sensor_frame,
                                        const PlaceDescriptorOptions& options = {});

/// The descriptor of a 2D scan in its laser frame. Cell (ring i, sector j): the fraction of sector
/// j's beams, returns and misses (scan.misses, taken as reaching max range) alike, whose range
/// passes ring i's inner edge. A sector without beams is empty (a 180-degree scan fills half).
/// Ring key: per ring the mean over used sectors: the share of the scan that reaches the ring, a
/// cumulative range histogram. Non-finite points are skipped.
PlaceDescriptor2D make_place_descriptor(const Scan2D& scan,
                                        const PlaceDescriptor2DOptions& options = {});

struct PlaceMatch {
  /// In [0, 1]: the mean over the sectors both use of 1 - cosine similarity of the columns, at the
  /// best column shift. 1 when nothing compares (an empty descriptor, grids of other sizes, or
  /// fewer than half of the smaller descriptor's used sectors overlap at any shift).
  double distance = 1.0;
  /// Radians in (-pi, pi]: the heading of the query sensor in the candidate sensor's frame, the
  /// rotation of T_candidate^-1 T_query about z (the query turned left of the candidate: positive).
  /// Refined between sectors by a parabola through the distances of the neighbouring shifts.
  double yaw = 0.0;
};

/// Compares two scans' descriptors: the sector keys pick the few most promising column shifts,
/// the full grids are compared at those and their neighbours.
PlaceMatch compare(const PlaceDescriptor3D& query, const PlaceDescriptor3D& candidate);
PlaceMatch compare(const PlaceDescriptor2D& query, const PlaceDescriptor2D& candidate);

}  // namespace scanmatch
