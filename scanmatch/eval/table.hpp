#pragma once
// Result tables (the papers' tables in the benchmark): one title, a header and rows of cells,
// rendered as Markdown, CSV or HTML.

#include <string>
#include <vector>

namespace scanmatch {

struct ResultTable {
  std::string title;  ///< e.g. "ATE, % of path length (CTF-ICP Table 2)"
  std::string note;   ///< one line under the table (may be empty)
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
};

std::string to_markdown(const ResultTable& table);
/// CSV with the title as the first column of every row, so several tables share one file.
std::string to_csv(const ResultTable& table);
std::string to_html(const ResultTable& table);

}  // namespace scanmatch
