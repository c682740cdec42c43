#pragma once
// `scanmatch bench` as a library call: every method (and CTF-ICP's ablations) on every sequence,
// on identical frames, and the papers' tables from the results (ATE, frames per second, stage
// times, ablation, static drift, KITTI drift, the LOAM paper's accuracy score and ms per frame).
// Writes under OUT:
//   data/PRESET/            simulated data sets, kept and reused by later runs (see --data)
//   runs/SEQUENCE/VARIANT/  one run folder per variant (scanmatch/run/odometry_run.hpp)
//   tables.md, tables.csv   the tables; report.html (tables and the first sequence's plots) and
//                           report_SEQUENCE.html per sequence

#include <map>
#include <string>
#include <vector>

#include "scanmatch/eval/metrics.hpp"
#include "scanmatch/eval/table.hpp"
#include "scanmatch/run/odometry_run.hpp"

namespace scanmatch {

struct BenchmarkOptions {
  /// Simulator presets; both empty: the CTF-ICP paper's five data sets.
  std::vector<std::string> presets;
  std::vector<std::string> sequences;  ///< sequences (open_sequence specs) to add
  /// Ground truth of `sequences` from trajectory files, one per sequence in order (none: each
  /// sequence's own, or else a reference kept beside its frames, see reference_beside(); see
  /// SequenceOptions::reference).
  std::vector<std::string> references;
  std::vector<std::string> methods;  ///< empty: every 3D method of the paper comparison
  std::size_t frames = 0;            ///< per sequence; 0: all
  int threads = 1;                   ///< per method
  bool ablation = true;              ///< add "ctf-icp --no-fine" and "--no-map-update"
  bool quiet = false;                ///< no progress (failures are still reported on stderr)
  std::string out;                   ///< output folder (created)
  std::string data;                  ///< where simulated data sets are kept; empty: OUT/data
  std::string command_line;          ///< shown above the tables and in the report
};

/// One column of the tables: a method, or an ablation such as "ctf-icp --no-fine".
struct BenchmarkVariant {
  std::string name;
  OdometryConfig config;
  /// A peer this build lacks: the CMake option that builds it. Its cells read "not built" and
  /// the bench goes on without it.
  std::string not_built;
};

struct BenchmarkCell {
  bool ok = false;
  bool not_built = false;  ///< the variant is a peer this build lacks: not run
  std::string error;       ///< why the run failed
  RunSummary run;
  AteResult ate;  ///< against the sequence's ground truth (zero without one)
  KittiDriftResult kitti;
  double accuracy_score = 0.0;  ///< see accuracy_score()
  std::string folder;           ///< the run folder
};

struct BenchmarkSequence {
  std::string name, data_folder;
  std::string reference;  ///< the trajectory file used as ground truth (empty: the source's own)
  bool still = false;     ///< the ground truth does not move: drift tables instead of ATE
  double path_length = 0.0;
  std::map<std::string, BenchmarkCell> cells;  ///< by variant name
};

struct BenchmarkResult {
  std::vector<BenchmarkVariant> variants;
  std::vector<BenchmarkSequence> sequences;
  std::vector<ResultTable> tables;
  std::string markdown;  ///< tables.md
};

/// The methods, plus CTF-ICP's ablations when `ablation` and ctf-icp is among them. Throws Error
/// for an unknown method, before any work; a known peer this build lacks is kept, marked
/// not_built.
std::vector<BenchmarkVariant> benchmark_variants(const std::vector<std::string>& methods,
                                                 int threads, bool ablation);

/// The run folder name of a variant: words joined by '_', option dashes dropped
/// ("ctf-icp --no-fine" -> "ctf-icp_no-fine").
std::string variant_folder_name(const std::string& variant);

/// PRESET's data set under `data` (data/PRESET), simulated when missing or when it holds fewer
/// than `frames` frames (0: the preset's own length), reused otherwise. Returns its folder.
std::string cached_dataset(const std::string& preset, const std::string& data, std::size_t frames,
                           bool quiet);

/// The LOAM paper's accuracy score: after alignment by `poses`, the mean squared distance from
/// each point of a frame to its nearest neighbour in the previous frame (PCL's fitness score,
/// pairs within 1 m, frames downsampled to 0.25 m), averaged over up to 30 evenly spread
/// consecutive frame pairs of the sequence (an open_sequence spec). m^2; 0 for fewer than two
/// poses.
double accuracy_score(const std::string& sequence, const std::vector<Pose>& poses);

/// The tables of finished sequences: columns are `methods`; the ablation table appears when the
/// variants include it, the KITTI drift table when some path was long enough for it.
std::vector<ResultTable> benchmark_tables(const std::vector<BenchmarkSequence>& sequences,
                                          const std::vector<BenchmarkVariant>& variants,
                                          const std::vector<std::string>& methods);

/// Runs everything and writes OUT as described above. A variant that fails on a sequence is
/// reported on stderr and shown as "failed"; bad options throw Error before any work.
BenchmarkResult run_benchmark(BenchmarkOptions options);

}  // namespace scanmatch
