#pragma once
// What every run folder shares, 2D (map2d_run) and 3D (odometry_run): the folder, what kind of
// run it holds (summary.json's "kind", which run_folder reads back), timing.csv with a row per
// scan or frame from its record's description (core/record.hpp), summary.json's parts written
// from descriptions (loop closure), whole files written atomically. For the runs' .cpp files.

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>

#include "scanmatch/io/line_writer.hpp"
#include "scanmatch/io/record_csv.hpp"
#include "scanmatch/run/loop_closure_run.hpp"

namespace scanmatch {

/// summary.json's "kind" of a run folder: `scanmatch odometry` (3D, timing.csv of FrameStats) or
/// `scanmatch map2d` (2D, timing.csv of Scan2DStats).
inline constexpr const char* kOdometryRunKind = "odometry";
inline constexpr const char* kMap2DRunKind = "map2d";

/// Creates RUNDIR and its parents; throws Error naming it when it cannot.
void create_run_folder(const std::string& path);

/// timing.csv: the header of Record's description, then a row per scan or frame, each flushed
/// (an interrupted run keeps its rows).
template <typename Record>
class TimingWriter {
 public:
  explicit TimingWriter(const std::string& path) : out_(path) {
    out_.line(record_csv_header<Record>());
  }
  void write(std::size_t index, double timestamp, const Record& record) {
    out_.line(record_csv_row(index, timestamp, record));
  }

 private:
  LineWriter out_;
};

/// Writes `j` (indented by 2, a final newline) atomically: summary.json, loops.json.
void write_json_atomic(const std::string& path, const nlohmann::ordered_json& j);

/// Every field of a described record by its key (summary.json).
template <typename Record>
nlohmann::ordered_json record_json(const Record& record) {
  nlohmann::ordered_json j = nlohmann::ordered_json::object();
  for_each_field(record, [&](const char* key, const auto& field, const char*) { j[key] = field; });
  return j;
}

/// summary.json's "loop_closure": the counts' keys (mapping/loop_counts.hpp), then "accepted",
/// "ms_per_<item>", "thread" and "wait_ms_per_<item>" (`item`: "scan" or "frame").
template <typename Counts>
nlohmann::ordered_json loop_closure_json(const LoopClosureRecord<Counts>& loops,
                                         const std::string& item) {
  nlohmann::ordered_json j = record_json(loops.counts);
  j["accepted"] = loops.accepted;
  j["ms_per_" + item] = loops.ms_per_item;
  j["thread"] = loops.thread;
  j["wait_ms_per_" + item] = loops.wait_ms_per_item;
  return j;
}

}  // namespace scanmatch
