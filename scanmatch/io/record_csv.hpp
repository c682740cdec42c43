#pragma once
// timing.csv of a described record (core/record.hpp): a header line "index,timestamp,<every key
// of describe()>", then a row per scan or frame. Stage times have 3 decimals, other floating
// numbers 6 significant digits, flags are 0 or 1. The reader goes by column name: columns it does
// not know (a newer file) are skipped, fields without a column (an older file) keep their
// defaults.

#include <fmt/format.h>

#include <algorithm>
#include <cstddef>
#include <string>
#include <type_traits>
#include <vector>

#include "scanmatch/core/error.hpp"
#include "scanmatch/core/record.hpp"

namespace scanmatch {

namespace record_csv_detail {

struct Cells {
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

/// The cells of a line (a CRLF file's '\r' dropped).
std::vector<std::string> split_cells(std::string line);
/// The whole cell as the value; false when it is not one (bool: 0 or 1).
bool parse_cell(const std::string& cell, bool& value);
bool parse_cell(const std::string& cell, int& value);
bool parse_cell(const std::string& cell, std::size_t& value);
bool parse_cell(const std::string& cell, double& value);

/// The lines of `path` after its header, split into cells, each checked to be as long as the
/// header; throws Error naming the file (and line) for an empty file, a header without
/// `required_column` or a row of another length.
struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  std::vector<std::size_t> line_numbers;
};
Table read_table(const std::string& path, const char* required_column);

// Reads one row's cells into the fields that have a column.
struct Reader {
  const std::vector<std::string>& header;
  const std::vector<std::string>& cells;
  const std::string& path;
  const std::string where;  ///< "line N"

  template <typename T>
  void operator()(const char* key, T& field, const char*) {
    const auto column = std::find(header.begin(), header.end(), key);
    if (column == header.end()) return;
    const std::string& cell = cells[static_cast<std::size_t>(column - header.begin())];
    if (!parse_cell(cell, field))
      fail(path, where, std::string(key) + ": not a valid value: '" + cell + "'");
  }
};

}  // namespace record_csv_detail

template <typename Record>
std::string record_csv_header() {
  std::string line = "index,timestamp";
  const Record defaults{};
  for_each_field(defaults, [&](const char* key, const auto&, const char*) {
    line += ',';
    line += key;
  });
  return line;
}

template <typename Record>
std::string record_csv_row(std::size_t index, double timestamp, const Record& record) {
  record_csv_detail::Cells cells{fmt::format("{},{:.6f}", index, timestamp)};
  describe(record, cells);
  return cells.line;
}

/// Reads a timing.csv written by record_csv_header/row (and older files, by column name). Throws
/// Error naming the file and line for a malformed value, a row whose length differs from the
/// header's, or a header without `required_column` (a file of another record).
template <typename Record>
std::vector<TimingRow<Record>> read_record_csv(const std::string& path,
                                               const char* required_column) {
  const record_csv_detail::Table table = record_csv_detail::read_table(path, required_column);
  std::vector<TimingRow<Record>> rows;
  for (std::size_t r = 0; r < table.rows.size(); ++r) {
    TimingRow<Record> row;
    record_csv_detail::Reader reader{table.header, table.rows[r], path,
                                     "line " + std::to_string(table.line_numbers[r])};
    reader("index", row.index, nullptr);
    reader("timestamp", row.timestamp, nullptr);
    for_each_field(row.stats, reader);
    rows.push_back(row);
  }
  return rows;
}

}  // namespace scanmatch
