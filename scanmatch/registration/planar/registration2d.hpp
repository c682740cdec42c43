#pragma once
// 2D laser scan matching (docs/methods.md section 2): the paper's sparse-correspondence method and
// the baselines of its Table 1, registered by name through one table of methods. Scans and poses
// are core/scan2d.hpp's.
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

#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "scanmatch/core/scan2d.hpp"
#include "scanmatch/registration/planar/correspondence_path.hpp"

namespace scanmatch {

struct Registration2DOptions {
  std::string method = "sparse-icp";  ///< a name of registration_2d_methods()
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
  /// Correlative coarse search before any method (correlative_search.hpp, over the window
  /// below), for steps the local methods cannot bridge (long corridors, fast turns). It replaces
  /// sparse-icp's histogram and centroid stage. 0: off.
  double search_window = 0.0;               ///< m, +- in x and y around the initial guess
  double search_angle = 45.0 * M_PI / 180;  ///< rad, +- around the initial guess
  double search_resolution = 0.05;          ///< m, cells of the search's likelihood grid
  /// The search fills the reference's straight surfaces between beam neighbours up to this far
  /// apart (filled_surfaces in correlative_search.hpp), m; 0: scores against the samples alone.
  double search_fill_gap = 1.0;
  /// After the search, the method's pose replaces the search's only if the scans' mean surface
  /// distance there (surface_distance) is at most this much (m) above the search pose's; else the
  /// search's pose stands. In cluttered close-range scans (a dead end, people round the robot)
  /// sparse-icp sometimes walks 4-20 degrees off a good start (docs/planar.md). Negative: off.
  double fine_fit_margin = 0.001;
};

struct Registration2DResult {
  Pose2 transform = Pose2::Identity();  ///< maps current-scan points into the reference frame
  int iterations = 0;
  double error = 0.0;     ///< mean distance of the final correspondences, m
  std::size_t pairs = 0;  ///< correspondences used in the last step
  bool converged = false;
  /// The method's pose fitted worse than the search's (fine_fit_margin), which was kept.
  bool search_pose_kept = false;
};

class Reference2D;  // reference2d.hpp

/// How a method runs: `current` onto `reference` from `initial`, with checked options and scans.
/// What it builds of the reference it takes from `reference`, which keeps it for the next run.
using Registration2DRun = Registration2DResult(const Scan2D& current, const Reference2D& reference,
                                               const Registration2DOptions& options,
                                               const Pose2& initial);

/// One line of the method table.
struct Registration2DMethod {
  const char* name;
  std::size_t min_points;  ///< valid points each scan needs
  const char* builds;      ///< what the method builds before iterating
  Registration2DRun* run;
};
/// The 2D methods, in the order the CLI lists them; the first is the default.
const std::vector<Registration2DMethod>& registration_2d_methods();
const std::vector<std::string>& registration_2d_method_names();
/// The mean distance (m) from `current`'s points under `pose` to `reference`'s surfaces (the
/// segments between beam neighbours up to `max_gap` apart, else its points), each capped at `cap`:
/// a fit that compares poses the methods reached by different costs.
inline constexpr double kSurfaceDistanceCap = 0.2;  ///< m, surface_distance's default cap
double surface_distance(const Scan2D& current, const Scan2D& reference, const Pose2& pose,
                        double max_gap, double cap = kSurfaceDistanceCap);

/// The method run from `searched` (a correlative search's pose), kept only where it fits no worse
/// than `searched` by fine_fit_margin (else `searched` with search_pose_kept set).
/// options.search_window is ignored.
Registration2DResult refine_searched(const Scan2D& current, const Scan2D& reference,
                                     const Registration2DOptions& options, const Pose2& searched);
/// The same onto a prepared reference, whose structures serve every refinement onto it.
Registration2DResult refine_searched(const Scan2D& current, const Reference2D& reference,
                                     const Registration2DOptions& options, const Pose2& searched);

/// "sparse-icp, icp, ...": the names for help texts and errors.
std::string registration_2d_method_list();
/// The method named `name`; throws Error naming the valid methods when there is none.
const Registration2DMethod& registration_2d_method(const std::string& name);
/// Throws Error naming the valid methods unless `method` is one of them.
void check_registration_2d_method(const std::string& method);
/// Throws Error naming the problem unless the method is known and every option is in range (what
/// register_scans checks first; long runs check once before their first scan).
void check_registration_2d_options(const Registration2DOptions& options);

/// Registers `current` onto `reference` from `initial` (after the correlative search, when
/// `search_window` is set, and then as refine_searched). Throws Error for an unknown method,
/// options out of range, or scans too small to register.
Registration2DResult register_scans(const Scan2D& current, const Scan2D& reference,
                                    const Registration2DOptions& options,
                                    const Pose2& initial = Pose2::Identity());

}  // namespace scanmatch
