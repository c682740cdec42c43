#pragma once
// sparse-icp's correspondences (docs/methods.md section 2 steps 3-4): a path through the matrix of
// Manhattan distances between the current scan's points (columns) and the reference scan's
// (rows), both in beam order, and the rules that mark its invalid pairs.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace scanmatch {

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

struct CorrespondencePath {
  std::vector<int> row;     ///< reference index matched to each current point (the path)
  std::vector<bool> valid;  ///< kept after the invalid-pair rules
};

/// The path: start at the minimum of the first column, then for each next column move a 3x1
/// window from the previous row towards decreasing distance until its centre is the window's
/// minimum. A pair is kept only where the step from the previous pair is the normal one (next
/// reference index), its reference point is not shared with a neighbouring column (many-to-one),
/// and its Manhattan distance is at most `max_distance`. Where the window loses the surface
/// (distance above `max_distance`), the path is picked up again at the reference point nearest in
/// bearing. O(n + m) for overlapping scans. `rules` may relax the invalid-pair rules (default:
/// the paper).
CorrespondencePath correspondence_path(const std::vector<Eigen::Vector2d>& current,
                                       const std::vector<Eigen::Vector2d>& reference, bool circular,
                                       double max_distance, const PathRules& rules = {});

/// correspondence_path against one reference scan, many times (once per iteration): what it
/// needs of the reference is built once, when first needed.
class PathTracer {
 public:
  /// Keeps `reference` by reference: it must outlive the tracer and not change.
  PathTracer(const std::vector<Eigen::Vector2d>& reference, bool circular, double max_distance,
             const PathRules& rules);
  CorrespondencePath trace(const std::vector<Eigen::Vector2d>& current);

 private:
  /// The reference points sorted by bearing from the sensor: where the path is lost, the
  /// reference point nearest in bearing is where the reference would have seen a current point.
  struct BearingIndex {
    explicit BearingIndex(const std::vector<Eigen::Vector2d>& points);
    long nearest(const Eigen::Vector2d& p) const;  ///< index of the point nearest in bearing
    std::vector<std::pair<double, long>> sorted;
  };
  const std::vector<Eigen::Vector2d>& reference_;
  bool circular_;
  double max_distance_;
  PathRules rules_;
  std::optional<BearingIndex> bearings_;
};

}  // namespace scanmatch
