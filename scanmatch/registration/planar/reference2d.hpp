#pragma once
// A registration reference prepared for many registrations onto it: the scan with what the
// methods build of it (a k-d tree, a grid of its points, fitted lines), each made on first use
// and then kept. Loop closure registers onto one keyframe's submap again and again
// (loop_closure2d.hpp).

#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "scanmatch/core/scan2d.hpp"
#include "scanmatch/geometry/kdtree.hpp"
#include "scanmatch/geometry/point_grid2.hpp"
#include "scanmatch/registration/planar/line_fitting.hpp"

namespace scanmatch {

/// A reference scan, kept by reference (it must outlive this and not change), with its search
/// structures. Safe to use from several threads at once.
class Reference2D {
 public:
  explicit Reference2D(const Scan2D& scan) : scan_(scan) {}
  Reference2D(const Reference2D&) = delete;  // the structures refer to `scan_`'s points
  Reference2D& operator=(const Reference2D&) = delete;

  const Scan2D& scan() const { return scan_; }
  /// Of scan().points.
  const KdTree2& tree() const;
  /// Of scan().points, for nearest points within a radius: the nearest point as tree() finds it
  /// (of equally near points, the first), made in a fraction of its time.
  const PointGrid2& grid() const;
  /// fit_scan_lines(scan(), radius, max_gap).
  const std::vector<FittedLine>& lines(double radius, double max_gap) const;

 private:
  struct Lines {
    double radius, max_gap;
    std::vector<FittedLine> lines;
  };
  const Scan2D& scan_;
  mutable std::mutex mutex_;  // guards building the members below
  mutable std::optional<KdTree2> tree_;
  mutable std::optional<PointGrid2> grid_;
  mutable std::vector<std::unique_ptr<const Lines>> lines_;  // one per (radius, max_gap) asked
};

}  // namespace scanmatch
