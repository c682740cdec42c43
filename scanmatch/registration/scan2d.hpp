#pragma once
// 2D laser scan matching (METHODS.md section 2): the paper's sparse-correspondence method and the
// baselines of its Table 1. Scans are points in the laser frame, in beam order; poses are
// Eigen::Isometry2d (x, y, theta).
//
//   sparse-icp   angle-histogram rotation, (optionally) centroid translation, the
//                Manhattan-distance correspondence path with invalid pairs dropped, then the
//                closed-form point-to-line step against lines fitted to the reference (the
//                paper's SVD step on sample pairs is an option); docs/planar.md says where and
//                why the defaults differ from the paper
//   icp          point-to-point, brute-force nearest neighbours, SVD step
//   icp-kdtree   the same with a k-d tree
//   pl-icp       Censi's point-to-line ICP with its exact closed-form step (Lagrange multiplier)
//   normal-icp   point-to-point with pairs rejected when their normals disagree
//
// The 2D methods do not use the 3D Gauss-Newton solver: the paper's method and Censi's are defined
// by their closed-form steps (SVD, and the constrained quadratic), which are exact in one solve.

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "scanmatch/io/carmen.hpp"

namespace scanmatch {

using Pose2 = Eigen::Isometry2d;
Pose2 pose2(double x, double y, double theta);
Pose2 pose2(const Eigen::Vector3d& xytheta);  ///< from (x, y, theta), as CARMEN logs store poses
double pose2_angle(const Pose2& T);           ///< theta in (-pi, pi]

struct Scan2D {
  std::vector<Eigen::Vector2d> points;  ///< valid returns, in beam order, laser frame, m
  /// End points of no-return beams at the maximum range (free space for grid maps), laser frame.
  std::vector<Eigen::Vector2d> misses;
  bool circular = false;  ///< a 360-degree scan: the last beam neighbours the first
  /// Per point, when its beam was measured, s after the first beam (empty: not known). A
  /// spinning laser sweeps while it moves; Mapper2D deskews with these.
  std::vector<double> times;
};

/// Valid beams (finite, range in (min_range, max_range)) as points, in beam order; `circular`
/// when the beams cover the full circle. Beams at or beyond the maximum range become `misses`
/// at `miss_range` (0: the scan's max range). With `rotation_period` (s per turn of the laser's
/// mirror or head; 0: unknown) each point gets its time: beams are measured in order, one full
/// turn taking the period.
Scan2D scan_from_laser(const LaserScan2D& scan, double min_range = 0.05, double miss_range = 0.0,
                       double rotation_period = 0.0);

/// sparse-icp's invalid-pair rules. The paper keeps a pair only after the normal step (the next
/// reference index, `max_step` 1) and drops every pair whose reference point is shared with a
/// neighbouring column (many-to-one). Relaxed: steps of up to `max_step` rows are normal (a
/// reference point skipped where the current scan is sparser), and of the columns sharing a row
/// the nearest keeps it (still one-to-one) or all keep it (many-to-one: harmless when each pair
/// is a point against a line, not against the shared point).
struct PathRules {
  long max_step = 1;
  enum class Shared { drop, keep_nearest, keep_all } shared = Shared::drop;
  /// keep_all: a longer run of columns on one row is judged as keep_nearest. Many current points
  /// on one reference point mean the reference saw that surface at one point only (an edge, an
  /// occlusion): its line is no evidence for them.
  long max_run = 3;
};
/// "drop", "keep-nearest", "keep-all": the names the CLI and run summaries use.
const char* to_string(PathRules::Shared shared);
/// The inverse of to_string; throws Error naming the valid names.
PathRules::Shared parse_shared_rows(const std::string& name);

struct Registration2DOptions {
  std::string method = "sparse-icp";  ///< sparse-icp, icp, icp-kdtree, pl-icp, normal-icp
  int max_iterations = 50;
  double tolerance = 1e-4;  ///< m and rad: stop when a step is smaller than this
  /// m: the paper's threshold D (Manhattan distance) for sparse-icp; the Euclidean rejection
  /// distance of the baselines.
  double max_correspondence_distance = 0.5;
  /// sparse-icp coarse stage: the angle histogram's bin width, rad.
  double histogram_bin = 1.0 * M_PI / 180;
  /// sparse-icp coarse stage: histogram segments are extended to at least this length, m (0: the
  /// paper's consecutive points, whose directions are mostly noise at 1 % range noise).
  double histogram_min_segment = 0.15;
  /// sparse-icp coarse stage: the histogram rotation is searched within +- this of the initial
  /// guess, rad (rectilinear rooms give peaks every 90 degrees).
  double histogram_max_rotation = 30.0 * M_PI / 180;
  bool coarse_rotation = true;  ///< sparse-icp: angle-histogram rotation
  /// sparse-icp: centroid translation. Off by default: two scans see different parts of a room,
  /// so their centroids differ by more than the motion (on simulated pairs it turned 0 failures
  /// into 7 in 300). The paper's setting is true.
  bool coarse_translation = false;
  /// sparse-icp: each kept pair's reference point is moved to the nearest point of the reference
  /// segments beside it (to the previous and next beam). Two scans never sample a wall at the same
  /// places; matching samples to samples leaves a bias of up to half the beam spacing, which this
  /// removes (the fixed point becomes the point-to-line optimum). false: the paper's plain pairs.
  bool subsample_projection = true;
  /// sparse-icp's step on the kept pairs: "svd" (the paper: point-to-point, closed form) or
  /// "point-to-line" (Censi's closed form against the reference segment of each kept pair).
  std::string sparse_step = "point-to-line";
  /// sparse-icp stops at steps below this (m and rad) or `tolerance`, whichever is larger. Near
  /// the optimum the kept set gains or loses a pair or two each iteration, which moves the
  /// solution by about 0.1 mm, so a tighter stop only spins: on 300 simulated pairs 1e-3 gave
  /// 4.87 mm in 7 iterations, 1e-4 4.94 mm in 33.
  double sparse_tolerance = 1e-3;
  /// sparse-icp's invalid-pair rules. Relaxed by default: with a line per pair, several current
  /// points on one reference point's line are each a valid constraint, and dropping them (the
  /// paper) halves the pairs (on 1000 simulated pairs 152 of 330 kept, 4.25 mm; relaxed 299,
  /// 2.66 mm). PathRules{} is the paper's.
  PathRules path_rules{2, PathRules::Shared::keep_all};
  /// sparse-icp with the point-to-line step: the worst residuals beyond this fraction of the kept
  /// pairs are dropped each iteration (1: none, the paper).
  double sparse_keep_fraction = 0.95;
  /// sparse-icp stops (not converged) when fewer than this fraction of the current points keep
  /// a pair: the path has lost the surfaces the scans share, and further steps only wander.
  /// Meant for the relaxed path rules; the paper's one-to-one rules keep too few pairs from a
  /// poor start for it (0: off, the paper).
  double sparse_min_pairs = 0.1;
  /// sparse-icp with the point-to-line step: each kept pair's line is fitted to the reference
  /// points within this radius of its reference point (beam-order neighbours on one straight
  /// surface), m; where there is no such line (a corner, sparse returns), the segment to the
  /// nearer beam neighbour. 0: always that segment, as in Censi's PL-ICP.
  double sparse_line_radius = 0.3;
  /// pl-icp: the same fitted lines instead of Censi's two-point segments (0: Censi, the default).
  double pl_line_radius = 0.0;
  double normal_angle = 30.0 * M_PI / 180;  ///< rad, normal-icp's rejection threshold
  /// pl-icp: the worst pairs beyond this fraction are dropped each iteration (Censi's csm keeps
  /// 95 %).
  double keep_fraction = 0.95;
  /// Correlative coarse search before any method (two-level branch and bound over the window
  /// below), for steps the local methods cannot bridge (long corridors, fast turns). It replaces
  /// sparse-icp's histogram and centroid stage. 0: off.
  double search_window = 0.0;               ///< m, +- in x and y around the initial guess
  double search_angle = 45.0 * M_PI / 180;  ///< rad, +- around the initial guess
  double search_resolution = 0.05;          ///< m, cells of the search's likelihood grid
};

struct Registration2DResult {
  Pose2 transform = Pose2::Identity();  ///< maps current-scan points into the reference frame
  int iterations = 0;
  double error = 0.0;     ///< mean distance of the final correspondences, m
  std::size_t pairs = 0;  ///< correspondences used in the last step
  bool converged = false;
};

/// Registers `current` onto `reference` from `initial`. Throws Error for an unknown method or
/// scans too small to register (fewer than 5 points).
Registration2DResult register_scans(const Scan2D& current, const Scan2D& reference,
                                    const Registration2DOptions& options,
                                    const Pose2& initial = Pose2::Identity());

const std::vector<std::string>& registration_2d_method_names();
/// Throws Error naming the valid methods unless `method` is one of them.
void check_registration_2d_method(const std::string& method);

// The steps of sparse-icp, exposed for tests and reuse.

/// Rigid transform minimising sum |R p_i + t - q_i|^2 (SVD with reflection guard). Needs two
/// pairs or more.
Pose2 align_svd(const std::vector<Eigen::Vector2d>& from, const std::vector<Eigen::Vector2d>& to);

/// sparse-icp's coarse stage: the histogram rotation (within `max_rotation`) about the origin,
/// then the translation between the centroids. Returns the correction to apply to `current`.
Pose2 coarse_alignment_2d(const std::vector<Eigen::Vector2d>& current,
                          const std::vector<Eigen::Vector2d>& reference, double bin_width,
                          double max_rotation, bool rotation = true, bool translation = true,
                          double min_segment = 0.0);

struct CorrespondencePath {
  std::vector<int> row;     ///< reference index matched to each current point (the path)
  std::vector<bool> valid;  ///< kept after the invalid-pair rules
};
/// The Manhattan-distance correspondence path of METHODS.md section 2 steps 3-4: start at the
/// minimum of the first column, then for each next column move a 3x1 window from the previous
/// row towards decreasing distance until its centre is the window's minimum. A pair is kept only
/// where the step from the previous pair is the normal one (next reference index), its reference
/// point is not shared with a neighbouring column (many-to-one), and its Manhattan distance is at
/// most `max_distance`. Where the window loses the surface (distance above `max_distance`), the
/// column is searched in full once to pick the path up again. O(n + m) for overlapping scans.
/// `rules` may relax the invalid-pair rules (PathRules; default: the paper).
CorrespondencePath correspondence_path(const std::vector<Eigen::Vector2d>& current,
                                       const std::vector<Eigen::Vector2d>& reference, bool circular,
                                       double max_distance, const PathRules& rules = {});

/// Closed-form point-to-line step (Censi 2008): the transform minimising
/// sum (n_i . (R p_i + t - q_i))^2 exactly, through the Lagrange multiplier of the constraint
/// cos^2 + sin^2 = 1. Needs three pairs with non-parallel normals or more.
Pose2 solve_point_to_line(const std::vector<Eigen::Vector2d>& points,
                          const std::vector<Eigen::Vector2d>& line_points,
                          const std::vector<Eigen::Vector2d>& normals);

/// Correlative search: the pose within the window around `initial` whose transformed points best
/// hit a smoothed likelihood grid of the reference, found exactly at the grid's resolution by a
/// two-level branch and bound (a max-filtered grid bounds each block of translations).
Pose2 correlative_search(const Scan2D& current, const Scan2D& reference, const Pose2& initial,
                         double window, double angle_window, double resolution = 0.05);

}  // namespace scanmatch
