#pragma once
// `scanmatch bench2d` as a library call: the 2D paper's Table 1 on simulated Neato scan pairs
// (error and iterations per method, mean and spread, pairs per second), and the relative pose
// error of scan-to-scan mapping on CARMEN logs for every method and initial guess. Everything in
// one run, on the same scans; the tables are Markdown.

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "scanmatch/mapping2d/mapper2d.hpp"

namespace scanmatch {

/// Method names of the tables besides the 2D methods: sparse-icp with every setting as the paper
/// has it (centroid translation, consecutive-point histogram, plain sample pairs, SVD step,
/// one-to-one pairs), and Censi's PL-ICP with sparse-icp's fitted lines (not a baseline: it shows
/// what the lines alone bring).
inline constexpr const char* kSparseIcpPaper = "sparse-icp-paper";
inline constexpr const char* kPlIcpFitted = "pl-icp-fitted";

struct Benchmark2DOptions {
  /// Empty: every 2D method, sparse-icp-paper after the first and pl-icp-fitted last.
  std::vector<std::string> methods;
  std::vector<std::string> logs;  ///< CARMEN logs to map scan to scan (.log or .log.gz)
  std::size_t pairs = 1000;       ///< simulated scan pairs (0: no pair table)
  double max_translation = 0.2;   ///< m, largest offset of a pair
  double max_rotation_deg = 10.0;
  /// Log variants with the correlative search over +- this many m (0: none).
  double search_window = 1.3;
  std::string out;  ///< writes OUT/planar_tables.md when not empty
  bool quiet = false;
};

/// The registration options of a table's method name (a 2D method or one of the two above).
/// Throws Error for an unknown name.
Registration2DOptions benchmark2d_method(const std::string& name);

/// Runs the pair table, then one table per log. Each table is passed to `on_table` as soon as it
/// is done (they can take minutes); returns them all, as written to OUT/planar_tables.md. Bad
/// options throw Error before any work.
std::string run_benchmark2d(Benchmark2DOptions options,
                            const std::function<void(const std::string&)>& on_table = {});

}  // namespace scanmatch
