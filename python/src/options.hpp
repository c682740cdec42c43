#pragma once
// Keyword arguments onto an options struct, generically, from the one description of its fields
// (scanmatch/run/run_config_fields.hpp's describe()): every described field is a keyword, by its
// JSON key. Nested objects (e.g. "solver", "registration") take either a dict
// (solver={"max_iterations": 5}) or their fields directly (max_iterations=5) when that key is
// unique in the whole description; the dotted form ("solver.max_iterations") always works.

#include <pybind11/pybind11.h>

#include <cstdint>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <type_traits>
#include <vector>

#include "scanmatch/core/error.hpp"
#include "scanmatch/run/run_config_fields.hpp"

namespace scanmatch::python {

namespace py = pybind11;

class FieldTable {
 public:
  /// `function` names the caller in messages ("register()").
  template <typename Options>
  FieldTable(Options& options, std::string function) : function_(std::move(function)) {
    Collector collector{*this, ""};
    describe(options, collector);
  }

  /// Sets every keyword of `kwargs`; TypeError for unknown keys and wrong types.
  void apply(const py::kwargs& kwargs);
  void set(const std::string& key, py::handle value);
  /// Every field as {dotted key: value}.
  py::dict values() const;
  /// Every field as {dotted key: help text}.
  py::dict help() const;

 private:
  struct Field {
    std::function<void(py::handle)> assign;
    std::function<py::object()> get;
    std::string help;
  };

  struct Collector {
    FieldTable& table;
    std::string prefix;
    template <typename T>
    void operator()(const char* key, T& field, const char*, const char* help) {
      const std::string path = prefix + key;
      table.fields_[path] = {[this_table = &table, path, &field](py::handle value) {
                               this_table->assign(path, field, value);
                             },
                             [&field] { return get(field); }, help};
      table.leaves_[key].push_back(path);
    }
    template <typename S>
    void nested(const char* key, S& options) {
      const std::string path = prefix + key;
      table.nested_.insert(path);
      Collector inner{table, path + "."};
      describe(options, inner);
    }
  };

  template <typename T>
  static py::object get(const T& field) {
    if constexpr (std::is_enum_v<T>)
      return py::str(enum_name(field));
    else
      return py::cast(field);
  }

  // One per field type of the descriptions.
  void assign(const std::string& path, double& field, py::handle value) const;
  void assign(const std::string& path, int& field, py::handle value) const;
  void assign(const std::string& path, long& field, py::handle value) const;
  void assign(const std::string& path, std::uint32_t& field, py::handle value) const;
  void assign(const std::string& path, unsigned long& field, py::handle value) const;
  void assign(const std::string& path, bool& field, py::handle value) const;
  void assign(const std::string& path, std::string& field, py::handle value) const;
  /// Enumerations by name (enum_name / enum_from_name of config/*_fields.hpp).
  template <typename E, typename = std::enable_if_t<std::is_enum_v<E>>>
  void assign(const std::string& path, E& field, py::handle value) const {
    if (!py::isinstance<py::str>(value)) wrong_type(path, "a name", value);
    try {
      enum_from_name(value.cast<std::string>(), field);
    } catch (const Error& e) {
      throw py::value_error(function_ + ": option '" + path + "': " + e.what());
    }
  }
  [[noreturn]] void wrong_type(const std::string& path, const char* expected,
                               py::handle value) const;
  std::string valid_keys() const;

  std::string function_;
  std::map<std::string, Field> fields_;                     ///< by dotted path
  std::map<std::string, std::vector<std::string>> leaves_;  ///< last key -> dotted paths
  std::set<std::string> nested_;
};

}  // namespace scanmatch::python
