// The one description of a frame's statistics (odometry/frame_stats.hpp): timing.csv's header
// and rows, its reader and the stage statistics all cover every described field, so a new field
// reaches them with no other edit (test_odometry_run.cpp: a run folder holds them all); and the
// per-frame line writer they are written through.
#include <gtest/gtest.h>

#include <set>
#include <type_traits>

#include "scanmatch/core/error.hpp"
#include "scanmatch/io/line_writer.hpp"
#include "scanmatch/odometry/frame_stats.hpp"
#include "test_helpers.hpp"

using namespace scanmatch;
using scanmatch::testing::read_text;
using scanmatch::testing::TempDir;
using scanmatch::testing::write_text;

namespace {

// The keys and stage names of the description, in its order.
struct Described {
  std::vector<std::string> keys, stages;
  template <typename T>
  void operator()(const char* key, const T&, const char* help) {
    keys.push_back(key);
    EXPECT_GT(std::string(help).size(), 0u) << key;
  }
  void stage(const char* key, double ms, const char* name, const char* help) {
    (*this)(key, ms, help);
    stages.push_back(name);
  }
};

Described described() {
  Described d;
  const FrameStats stats;
  describe(stats, d);
  return d;
}

// A different value in every field (bool: true), exact in timing.csv's number formats.
FrameStats distinct_stats() {
  FrameStats stats;
  int next = 1;
  for_each_field(stats, [&](const char*, auto& field, const char*) {
    using T = std::remove_reference_t<decltype(field)>;
    if constexpr (std::is_same_v<T, bool>)
      field = true;
    else if constexpr (std::is_floating_point_v<T>)
      field = next + 0.25;
    else
      field = static_cast<T>(next);
    ++next;
  });
  return stats;
}

std::vector<double> field_values(const FrameStats& stats) {
  std::vector<double> values;
  for_each_field(stats, [&](const char*, const auto& field, const char*) {
    values.push_back(static_cast<double>(field));
  });
  return values;
}

}  // namespace

TEST(FrameStats, TimingCsvHeaderIsIndexTimestampThenEveryDescribedKey) {
  std::string expected = "index,timestamp";
  for (const std::string& key : described().keys) expected += "," + key;
  EXPECT_EQ(timing_csv_header(), expected);
  // The columns existing run folders and tools know come first, in their order.
  EXPECT_EQ(timing_csv_header().rfind(
                "index,timestamp,preprocess_ms,coarse_ms,fine_ms,map_ms,total_ms,points_in,"
                "points_downsampled,iterations,condition_number,degenerate_directions,bridged,",
                0),
            0u);
}

TEST(FrameStats, TimingCsvRowsKeepTheirNumberFormats) {
  FrameStats s;
  s.preprocess_ms = 1.23456;
  s.coarse_ms = 2.0;
  s.fine_ms = 0.0005;
  s.map_ms = 10.1;
  s.total_ms = 13.4;
  s.points_in = 120000;
  s.points_downsampled = 8123;
  s.iterations = 17;
  s.condition_number = 1234567.0;
  s.degenerate_directions = 1;
  s.bridged = true;
  s.prior_uncertain = true;
  s.recovered = true;
  s.prior_miss_m = 0.123456789;
  s.elevation_correction_deg = 0.2488;
  EXPECT_EQ(timing_csv_row(4, 1234.5, s),
            "4,1234.500000,1.235,2.000,0.001,10.100,13.400,120000,8123,17,1.23457e+06,1,1,1,1,0,0,"
            "0.123457,0,0,0,0,0.2488");
  EXPECT_EQ(timing_csv_row(0, 0.0, FrameStats{}),
            "0,0.000000,0.000,0.000,0.000,0.000,0.000,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0");
}

TEST(FrameStats, EveryDescribedFieldRoundTripsThroughTimingCsv) {
  TempDir dir;
  const FrameStats stats = distinct_stats();
  {
    LineWriter out(dir.file("timing.csv"));
    out.line(timing_csv_header());
    out.line(timing_csv_row(0, 10.5, FrameStats{}));
    out.line(timing_csv_row(1, 10.625, stats));
  }
  const std::vector<FrameRecord> rows = read_timing_csv(dir.file("timing.csv"));
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[1].index, 1u);
  EXPECT_EQ(rows[1].timestamp, 10.625);
  EXPECT_EQ(field_values(rows[0].stats), field_values(FrameStats{}));
  const std::vector<double> values = field_values(rows[1].stats);
  EXPECT_EQ(values, field_values(stats));
  EXPECT_EQ(values.size(), described().keys.size());
  std::size_t flags = 0;
  for_each_field(stats, [&](const char*, const auto& field, const char*) {
    flags += std::is_same_v<std::remove_cvref_t<decltype(field)>, bool>;
  });
  EXPECT_EQ(std::set<double>(values.begin(), values.end()).size(), values.size() - flags + 1)
      << "every field but the flags (all true) holds its own value";
}

TEST(FrameStats, ReadingTimingCsvIsByColumnName) {
  TempDir dir;
  // An older file without most columns; a newer one with a column this build does not know, in
  // another order, with CRLF line ends.
  write_text(dir.file("old.csv"),
             "index,timestamp,total_ms,bridged\n0,1.5,12.250,0\n1,1.6,9.5,1\n");
  write_text(dir.file("new.csv"),
             "bridged,index,future_stat,total_ms,timestamp\r\n1,7,abc,3.000,2.25\r\n\r\n");
  const auto old_rows = read_timing_csv(dir.file("old.csv"));
  ASSERT_EQ(old_rows.size(), 2u);
  EXPECT_EQ(old_rows[0].stats.total_ms, 12.25);
  EXPECT_TRUE(old_rows[1].stats.bridged);
  EXPECT_EQ(old_rows[1].stats.points_in, 0u);
  const auto new_rows = read_timing_csv(dir.file("new.csv"));
  ASSERT_EQ(new_rows.size(), 1u);
  EXPECT_EQ(new_rows[0].index, 7u);
  EXPECT_EQ(new_rows[0].timestamp, 2.25);
  EXPECT_EQ(new_rows[0].stats.total_ms, 3.0);
  EXPECT_TRUE(new_rows[0].stats.bridged);
}

TEST(FrameStats, AMalformedTimingCsvNamesTheFileLineAndColumn) {
  TempDir dir;
  const auto error_of = [&](const std::string& text) {
    write_text(dir.file("timing.csv"), text);
    try {
      read_timing_csv(dir.file("timing.csv"));
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string header = timing_csv_header() + "\n";
  const std::string good = timing_csv_row(0, 0.0, FrameStats{}) + "\n";
  EXPECT_EQ(error_of(header + good + "1,0.1,x" + good.substr(good.find(",0.000,") + 6)),
            dir.file("timing.csv") + ": line 3: preprocess_ms: not a valid value: 'x'");
  EXPECT_EQ(error_of(header + "0,0.1,1,2\n"), dir.file("timing.csv") + ": line 2: expected " +
                                                  std::to_string(described().keys.size() + 2) +
                                                  " values, found 4");
  EXPECT_EQ(error_of("index,timestamp,points_in,total_ms\n0,0,-5,1\n"),
            dir.file("timing.csv") + ": line 2: points_in: not a valid value: '-5'");
  EXPECT_EQ(error_of("index,timestamp,total_ms,bridged\n0,0,1,yes\n"),
            dir.file("timing.csv") + ": line 2: bridged: not a valid value: 'yes'");
  EXPECT_EQ(error_of("scan,ms\n"), dir.file("timing.csv") + ": line 1: no total_ms column");
}

TEST(FrameStats, StageStatisticsCoverEveryDescribedStage) {
  FrameStats a, b;
  a.total_ms = 4.0;
  b.total_ms = 8.0;
  b.map_ms = 2.0;
  const std::vector<StageStatistics> stages = stage_statistics({a, b});
  std::vector<std::string> names;
  for (const StageStatistics& s : stages) names.push_back(s.name);
  EXPECT_EQ(names, described().stages);
  EXPECT_EQ(names,
            (std::vector<std::string>{"preprocess", "coarse", "fine", "map_update", "total"}));
  EXPECT_EQ(stages.back().mean_ms, 6.0);
  EXPECT_EQ(stages.back().max_ms, 8.0);
  EXPECT_EQ(stages[3].mean_ms, 1.0);
  EXPECT_EQ(stage_statistics({}).size(), names.size());
}

TEST(LineWriter, FlushesEachLineAndNamesAFileItCannotCreate) {
  TempDir dir;
  LineWriter out(dir.file("lines.txt"));
  out.line("first");
  EXPECT_EQ(read_text(dir.file("lines.txt")), "first\n");  // readable while still open
  out.line("second");
  EXPECT_EQ(read_text(dir.file("lines.txt")), "first\nsecond\n");
  try {
    LineWriter bad(dir.file("no/such/folder/lines.txt"));
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(dir.file("no/such/folder/lines.txt") + ": cannot create"),
              std::string::npos);
  }
}
