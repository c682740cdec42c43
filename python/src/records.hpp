#pragma once
// Python dictionaries of described records (scanmatch/core/record.hpp): FrameStats, Scan2DStats,
// the loop-closure counts. Their keys are the description's, the same as timing.csv's and
// summary.json's.

#include <pybind11/pybind11.h>

#include <string>

#include "scanmatch/core/record.hpp"

namespace scanmatch::python {

namespace py = pybind11;

/// Every field of `record` by its key.
template <typename Record>
py::dict record_dict(const Record& record) {
  py::dict d;
  for_each_field(record, [&](const char* key, const auto& field, const char*) { d[key] = field; });
  return d;
}

/// `intro`, then each key of the description with its help text (a docstring).
template <typename Record>
std::string record_doc(const std::string& intro) {
  std::string text = intro;
  const Record defaults{};
  for_each_field(defaults, [&](const char* key, const auto&, const char* help) {
    text += std::string("\n  ") + key + ": " + help;
  });
  return text;
}

}  // namespace scanmatch::python
