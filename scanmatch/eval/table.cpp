#include "scanmatch/eval/table.hpp"

#include "scanmatch/eval/svg_plot.hpp"

namespace scanmatch {
namespace {

std::string csv_cell(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

std::string row_markdown(const std::vector<std::string>& cells, std::size_t columns) {
  std::string line = "|";
  for (std::size_t i = 0; i < columns; ++i) {
    line.append(" ");
    if (i < cells.size()) line.append(cells[i]);
    line.append(" |");
  }
  line.append("\n");
  return line;
}

}  // namespace

std::string to_markdown(const ResultTable& t) {
  std::string md = "### ";
  md.append(t.title).append("\n\n").append(row_markdown(t.header, t.header.size())).append("|");
  for (std::size_t i = 0; i < t.header.size(); ++i) md.append(i == 0 ? "---|" : "---:|");
  md.append("\n");
  for (const auto& row : t.rows) md += row_markdown(row, t.header.size());
  if (!t.note.empty()) md.append("\n").append(t.note).append("\n");
  md.append("\n");
  return md;
}

std::string to_csv(const ResultTable& t) {
  std::string csv = "table";
  for (const auto& h : t.header) csv.append(",").append(csv_cell(h));
  csv.append("\n");
  for (const auto& row : t.rows) {
    csv.append(csv_cell(t.title));
    for (const auto& cell : row) csv.append(",").append(csv_cell(cell));
    csv.append("\n");
  }
  return csv;
}

std::string to_html(const ResultTable& t) {
  std::string html = "<h3>" + html_escape(t.title) + "</h3>\n<table><tr>";
  for (const auto& h : t.header) html += "<th>" + html_escape(h) + "</th>";
  html += "</tr>\n";
  for (const auto& row : t.rows) {
    html += "<tr>";
    for (const auto& cell : row) html += "<td>" + html_escape(cell) + "</td>";
    html += "</tr>\n";
  }
  html += "</table>\n";
  if (!t.note.empty()) html += "<p>" + html_escape(t.note) + "</p>\n";
  return html;
}

}  // namespace scanmatch
