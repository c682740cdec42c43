#pragma once
// A frame's timing and diagnostics (Odometry::last_stats()) and the one description of them, a
// record (core/record.hpp): every field's key, the field and a help text. Everything that writes
// or reads the statistics comes from describe(): timing.csv's columns and rows and its reader
// (below, io/record_csv.hpp), the per-stage mean and max of summary.json, and Python's
// Odometry.stats dictionaries. A new statistic is a member of FrameStats and one line in
// describe(). stage() is the time of a pipeline stage in ms: summary.json reports its mean and max
// under "stages" as `stage`.

#include <concepts>
#include <cstddef>
#include <string>
#include <type_traits>
#include <vector>

#include "scanmatch/core/record.hpp"

namespace scanmatch {

/// One frame of the odometry; the meaning of each field is its help text in describe().
struct FrameStats {
  double preprocess_ms = 0, coarse_ms = 0, fine_ms = 0, map_ms = 0, total_ms = 0;
  std::size_t points_in = 0, points_downsampled = 0;
  int iterations = 0;
  double condition_number = 0;
  int degenerate_directions = 0;
  bool bridged = false;
  // Health of the frame: how far to trust it.
  bool prior_uncertain = false;
  bool recovered = false;
  bool global_start = false;
  bool redeskewed = false;
  double prior_miss_m = 0, prior_miss_deg = 0;
  double fine_paired_fraction = 0;
  double coarse_fine_m = 0, coarse_fine_deg = 0;
  double elevation_correction_deg = 0;
};

template <typename Stats, typename Visitor>
requires std::same_as<std::remove_const_t<Stats>, FrameStats>
void describe(Stats& s, Visitor& v) {
  v.stage("preprocess_ms", s.preprocess_ms, "preprocess",
          "crops, voxel filter and deskew (and the beam elevation estimate's pairs), ms");
  v.stage("coarse_ms", s.coarse_ms, "coarse",
          "ctf-icp's coarse NDT stage, or the frame-to-frame registration, ms");
  v.stage("fine_ms", s.fine_ms, "fine", "ctf-icp's fine stage (frame to map), ms");
  v.stage("map_ms", s.map_ms, "map_update",
          "ctf-icp's map update and NDT grid, ms (threads > 1: what the frame waited for the last "
          "frame's, which runs beside its preprocessing, plus its own start)");
  v.stage("total_ms", s.total_ms, "total", "the whole frame (register_frame), ms");
  v("points_in", s.points_in, "points of the frame as given");
  v("points_downsampled", s.points_downsampled, "points left after the crops and voxel filter");
  v("iterations", s.iterations, "registration iterations, coarse plus fine");
  v("condition_number", s.condition_number, "of the last stage's information matrix");
  v("degenerate_directions", s.degenerate_directions,
    "directions the fine stage left at the motion prior");
  v("bridged", s.bridged, "the frame could not be registered: the motion prior was used");
  v("prior_uncertain", s.prior_uncertain,
    "the motion prior was not trusted (first motion, irregular time step, after a bridged frame or "
    "one that missed its prior): other coarse starts and a wider gate");
  v("recovered", s.recovered,
    "ctf-icp: another coarse start (the identity, a scaled or a turned prior) scored better than "
    "the prior's own result, and replaced it");
  v("global_start", s.global_start,
    "ctf-icp: the first motion left little of the frame overlapping the first one, and its pose "
    "came from a registration onto it with no prior (global_start_below)");
  v("redeskewed", s.redeskewed,
    "the registered motion missed the prior the frame was deskewed by (redeskew_translation, "
    "redeskew_rotation): deskewed again by it and registered again");
  v("prior_miss_m", s.prior_miss_m, "distance of the estimate from the motion prior, m");
  v("prior_miss_deg", s.prior_miss_deg, "rotation of the estimate from the motion prior, deg");
  v("fine_paired_fraction", s.fine_paired_fraction,
    "ctf-icp: fraction of the frame's points paired with a map plane by the fine stage (a thin "
    "map or little overlap: below about 0.3)");
  v("coarse_fine_m", s.coarse_fine_m,
    "ctf-icp: distance between the coarse and the fine result, m (large: the stages disagree)");
  v("coarse_fine_deg", s.coarse_fine_deg,
    "ctf-icp: rotation between the coarse and fine result, deg");
  v("elevation_correction_deg", s.elevation_correction_deg,
    "the beam elevation correction the frame was preprocessed with, deg (elevation_estimate: 0 "
    "until the first moving frames decide one)");
}

// timing.csv: a header line "index,timestamp,<every key of describe()>", then a row a frame.
// Stage times have 3 decimals, other numbers 6 significant digits, `bridged` is 0 or 1.

std::string timing_csv_header();
std::string timing_csv_row(std::size_t index, double timestamp, const FrameStats& stats);

/// One row of timing.csv read back.
using FrameRecord = TimingRow<FrameStats>;

/// Reads timing.csv by column name: columns it does not know (a newer file) are skipped, fields
/// without a column (an older file) keep their defaults. Throws Error naming the file and line
/// for a malformed value or a row whose length differs from the header's.
std::vector<FrameRecord> read_timing_csv(const std::string& path);

/// Mean and max of one stage time over a run (summary.json's "stages").
struct StageStatistics {
  std::string name;  ///< the stage's name in describe() ("map_update")
  double mean_ms = 0.0, max_ms = 0.0;
};

/// Every stage of describe(), in its order (zeros for no frames).
std::vector<StageStatistics> stage_statistics(const std::vector<FrameStats>& frames);

}  // namespace scanmatch
