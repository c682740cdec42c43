#include "scanmatch/odometry/frame_stats.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <sstream>

#include "scanmatch/core/error.hpp"
#include "scanmatch/io/file_util.hpp"

namespace scanmatch {
namespace {

struct CsvKeys {
  std::string line = "index,timestamp";
  template <typename T>
  void operator()(const char* key, const T&, const char*) {
    line += ',';
    line += key;
  }
  void stage(const char* key, double ms, const char*, const char* help) { (*this)(key, ms, help); }
};

struct CsvCells {
  std::string line;
  template <typename T>
  void operator()(const char*, const T& field, const char*) {
    if constexpr (std::is_same_v<T, bool>)
      line += field ? ",1" : ",0";
    else if constexpr (std::is_floating_point_v<T>)
      line += fmt::format(",{:.6g}", field);
    else
      line += fmt::format(",{}", field);
  }
  void stage(const char*, double ms, const char*, const char*) {
    line += fmt::format(",{:.3f}", ms);
  }
};

// The cells of a line (a CRLF file's '\r' dropped).
std::vector<std::string> split_cells(std::string line) {
  if (!line.empty() && line.back() == '\r') line.pop_back();
  std::vector<std::string> cells;
  std::istringstream in(line);
  for (std::string cell; std::getline(in, cell, ',');) cells.push_back(cell);
  if (!line.empty() && line.back() == ',') cells.emplace_back();  // a trailing empty cell
  return cells;
}

// The whole cell as a T; false when it is not one (bool: 0 or 1).
template <typename T>
bool parse_cell(const std::string& cell, T& value) {
  const char* end = cell.data() + cell.size();
  if constexpr (std::is_same_v<T, bool>) {
    if (cell != "0" && cell != "1") return false;
    value = cell == "1";
    return true;
  } else {
    const auto [ptr, ec] = std::from_chars(cell.data(), end, value);
    return ec == std::errc() && ptr == end && !cell.empty();
  }
}

// Reads one row's cells into the fields that have a column.
struct CsvReader {
  const std::vector<std::string>& header;
  const std::vector<std::string>& cells;
  const std::string& path;
  const std::string& where;  ///< "line N"

  template <typename T>
  void operator()(const char* key, T& field, const char*) {
    const auto column = std::find(header.begin(), header.end(), key);
    if (column == header.end()) return;
    const std::string& cell = cells[static_cast<std::size_t>(column - header.begin())];
    if (!parse_cell(cell, field))
      fail(path, where, std::string(key) + ": not a valid value: '" + cell + "'");
  }
  void stage(const char* key, double& ms, const char*, const char* help) { (*this)(key, ms, help); }
};

// Adds a frame's stage times to the stages, in the order of describe().
struct StageSums {
  std::vector<StageStatistics> stages;
  std::size_t next = 0;
  template <typename T>
  void operator()(const char*, const T&, const char*) {}
  void stage(const char*, double ms, const char* name, const char*) {
    if (next == stages.size()) stages.push_back({name});
    StageStatistics& s = stages[next++];
    s.mean_ms += ms;
    s.max_ms = std::max(s.max_ms, ms);
  }
};

}  // namespace

std::string timing_csv_header() {
  CsvKeys keys;
  const FrameStats defaults;
  describe(defaults, keys);
  return keys.line;
}

std::string timing_csv_row(std::size_t index, double timestamp, const FrameStats& stats) {
  CsvCells cells{fmt::format("{},{:.6f}", index, timestamp)};
  describe(stats, cells);
  return cells.line;
}

std::vector<FrameRecord> read_timing_csv(const std::string& path) {
  std::istringstream in(read_file_bytes(path));
  std::string line;
  if (!std::getline(in, line)) fail(path, "empty file");
  const std::vector<std::string> header = split_cells(line);
  if (std::find(header.begin(), header.end(), "total_ms") == header.end())
    fail(path, "line 1", "no total_ms column");
  std::vector<FrameRecord> rows;
  for (std::size_t number = 2; std::getline(in, line); ++number) {
    if (line.empty() || line == "\r") continue;
    const std::string where = "line " + std::to_string(number);
    const std::vector<std::string> cells = split_cells(line);
    if (cells.size() != header.size())
      fail(path, where,
           "expected " + std::to_string(header.size()) + " values, found " +
               std::to_string(cells.size()));
    FrameRecord row;
    CsvReader reader{header, cells, path, where};
    reader("index", row.index, nullptr);
    reader("timestamp", row.timestamp, nullptr);
    describe(row.stats, reader);
    rows.push_back(row);
  }
  return rows;
}

std::vector<StageStatistics> stage_statistics(const std::vector<FrameStats>& frames) {
  StageSums sum;
  const FrameStats defaults;
  describe(defaults, sum);  // the names, also without frames
  for (const FrameStats& frame : frames) {
    sum.next = 0;
    describe(frame, sum);
  }
  if (!frames.empty())
    for (StageStatistics& s : sum.stages) s.mean_ms /= static_cast<double>(frames.size());
  return sum.stages;
}

}  // namespace scanmatch
