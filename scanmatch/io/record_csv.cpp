#include "scanmatch/io/record_csv.hpp"

#include <charconv>
#include <sstream>

#include "scanmatch/io/file_util.hpp"

namespace scanmatch::record_csv_detail {
namespace {

template <typename T>
bool parse_number(const std::string& cell, T& value) {
  const char* end = cell.data() + cell.size();
  const auto [ptr, ec] = std::from_chars(cell.data(), end, value);
  return ec == std::errc() && ptr == end && !cell.empty();
}

}  // namespace

std::vector<std::string> split_cells(std::string line) {
  if (!line.empty() && line.back() == '\r') line.pop_back();
  std::vector<std::string> cells;
  std::istringstream in(line);
  for (std::string cell; std::getline(in, cell, ',');) cells.push_back(cell);
  if (!line.empty() && line.back() == ',') cells.emplace_back();  // a trailing empty cell
  return cells;
}

bool parse_cell(const std::string& cell, bool& value) {
  if (cell != "0" && cell != "1") return false;
  value = cell == "1";
  return true;
}
bool parse_cell(const std::string& cell, int& value) {
  return parse_number(cell, value);
}
bool parse_cell(const std::string& cell, std::size_t& value) {
  return parse_number(cell, value);
}
bool parse_cell(const std::string& cell, double& value) {
  return parse_number(cell, value);
}

Table read_table(const std::string& path, const char* required_column) {
  std::istringstream in(read_file_bytes(path));
  std::string line;
  if (!std::getline(in, line)) fail(path, "empty file");
  Table table;
  table.header = split_cells(line);
  if (std::find(table.header.begin(), table.header.end(), required_column) == table.header.end())
    fail(path, "line 1", std::string("no ") + required_column + " column");
  for (std::size_t number = 2; std::getline(in, line); ++number) {
    if (line.empty() || line == "\r") continue;
    std::vector<std::string> cells = split_cells(line);
    if (cells.size() != table.header.size())
      fail(path, "line " + std::to_string(number),
           "expected " + std::to_string(table.header.size()) + " values, found " +
               std::to_string(cells.size()));
    table.rows.push_back(std::move(cells));
    table.line_numbers.push_back(number);
  }
  return table;
}

}  // namespace scanmatch::record_csv_detail
