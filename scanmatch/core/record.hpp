#pragma once
// A record: a struct of per-scan or per-frame statistics (odometry/frame_stats.hpp's FrameStats,
// mapping2d/scan2d_stats.hpp's Scan2DStats) or of counts (mapping/loop_counts.hpp), described
// once by a describe(record, visitor) beside it: every field's key, the field and a help text.
// Everything that writes or reads a record comes from that description: timing.csv's columns,
// rows and reader (io/record_csv.hpp), summary.json's keys and Python's dictionaries.
//
// A visitor provides
//   template <class T> void operator()(const char* key, T& field, const char* help);
//   void stage(const char* key, double& ms, const char* stage, const char* help);
// stage() is a time in ms (a pipeline stage named `stage`, e.g. summary.json's mean and max per
// stage); a record without times never calls it. A visitor of a const record gets const fields.
// for_each_field() visits both kinds with one callable.

#include <cstddef>
#include <type_traits>

namespace scanmatch {

namespace record_detail {
template <typename F>
struct EveryField {
  F& f;
  template <typename T>
  void operator()(const char* key, T& field, const char* help) {
    f(key, field, help);
  }
  template <typename T>
  void stage(const char* key, T& ms, const char*, const char* help) {
    f(key, ms, help);
  }
};
}  // namespace record_detail

/// A record with its scan's or frame's index and timestamp: a row of timing.csv.
template <typename Record>
struct TimingRow {
  std::size_t index = 0;
  double timestamp = 0;
  Record stats;
};

/// Calls f(key, field, help) for every field of `record`, stage times included.
template <typename Record, typename F>
void for_each_field(Record& record, F&& f) {
  record_detail::EveryField<std::remove_reference_t<F>> visitor{f};
  describe(record, visitor);
}

}  // namespace scanmatch
