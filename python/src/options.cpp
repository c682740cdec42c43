#include "options.hpp"

#include <cmath>
#include <limits>

#include "scanmatch/core/error.hpp"

namespace scanmatch::python {
namespace {

bool is_numpy_scalar(py::handle value, const char* kind) {
  const py::module_ numpy = py::module_::import("numpy");
  return py::isinstance(value, numpy.attr(kind));
}

bool is_integer(py::handle value) {
  return !PyBool_Check(value.ptr()) &&
         (PyLong_Check(value.ptr()) || is_numpy_scalar(value, "integer"));
}

bool is_real(py::handle value) {
  return is_integer(value) || PyFloat_Check(value.ptr()) || is_numpy_scalar(value, "floating");
}

}  // namespace

void FieldTable::wrong_type(const std::string& path, const char* expected, py::handle value) const {
  throw py::type_error(function_ + ": option '" + path + "' must be " + expected + ", got " +
                       py::repr(value).cast<std::string>() + " (" +
                       py::str(py::type::handle_of(value).attr("__name__")).cast<std::string>() +
                       ")");
}

void FieldTable::assign(const std::string& path, double& field, py::handle value) const {
  if (!is_real(value)) wrong_type(path, "a number", value);
  const double v = value.cast<double>();
  if (std::isnan(v)) throw py::value_error(function_ + ": option '" + path + "' is NaN");
  field = v;
}

void FieldTable::assign(const std::string& path, int& field, py::handle value) const {
  if (!is_integer(value)) wrong_type(path, "an integer", value);
  const long long v = value.cast<long long>();
  if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max())
    throw py::value_error(function_ + ": option '" + path + "' is out of range");
  field = static_cast<int>(v);
}

void FieldTable::assign(const std::string& path, long& field, py::handle value) const {
  if (!is_integer(value)) wrong_type(path, "an integer", value);
  field = static_cast<long>(value.cast<long long>());
}

void FieldTable::assign(const std::string& path, std::uint32_t& field, py::handle value) const {
  if (!is_integer(value)) wrong_type(path, "a non-negative integer", value);
  const long long v = value.cast<long long>();
  if (v < 0 || v > std::numeric_limits<std::uint32_t>::max())
    throw py::value_error(function_ + ": option '" + path + "' must be a non-negative integer");
  field = static_cast<std::uint32_t>(v);
}

void FieldTable::assign(const std::string& path, unsigned long& field, py::handle value) const {
  if (!is_integer(value)) wrong_type(path, "a non-negative integer", value);
  const long long v = value.cast<long long>();
  if (v < 0) throw py::value_error(function_ + ": option '" + path + "' must not be negative");
  field = static_cast<unsigned long>(v);
}

void FieldTable::assign(const std::string& path, bool& field, py::handle value) const {
  if (!PyBool_Check(value.ptr()) && !is_numpy_scalar(value, "bool_"))
    wrong_type(path, "True or False", value);
  field = py::cast<bool>(py::bool_(py::reinterpret_borrow<py::object>(value)));
}

void FieldTable::assign(const std::string& path, std::string& field, py::handle value) const {
  if (!py::isinstance<py::str>(value)) wrong_type(path, "a string", value);
  field = value.cast<std::string>();
}

std::string FieldTable::valid_keys() const {
  std::string list;
  for (const auto& [leaf, paths] : leaves_) {
    if (!list.empty()) list += ", ";
    list += paths.size() == 1 ? leaf : paths.front();
    for (std::size_t i = 1; i < paths.size(); ++i) list += ", " + paths[i];
  }
  return list;
}

void FieldTable::set(const std::string& key, py::handle value) {
  if (const auto field = fields_.find(key); field != fields_.end()) {
    field->second.assign(value);
    return;
  }
  if (nested_.count(key)) {
    if (!py::isinstance<py::dict>(value))
      throw py::type_error(function_ + ": option '" + key +
                           "' takes a dict of its fields, e.g. {'" + key + "': ...}");
    for (const auto& [k, v] : value.cast<py::dict>()) {
      if (!py::isinstance<py::str>(k))
        throw py::type_error(function_ + ": option '" + key + "' has a non-string key");
      set(key + "." + k.cast<std::string>(), v);
    }
    return;
  }
  if (const auto leaf = leaves_.find(key); leaf != leaves_.end()) {
    if (leaf->second.size() == 1) {
      fields_.at(leaf->second.front()).assign(value);
      return;
    }
    std::string paths;
    for (const auto& p : leaf->second) paths += (paths.empty() ? "" : ", ") + p;
    throw py::type_error(function_ + ": option '" + key + "' is ambiguous; use one of " + paths +
                         " (as **{'" + leaf->second.front() + "': ...})");
  }
  throw py::type_error(function_ + ": unknown option '" + key + "' (valid: " + valid_keys() + ")");
}

void FieldTable::apply(const py::kwargs& kwargs) {
  for (const auto& [key, value] : kwargs) set(key.cast<std::string>(), value);
}

py::dict FieldTable::values() const {
  py::dict out;
  for (const auto& [path, field] : fields_) out[py::str(path)] = field.get();
  return out;
}

py::dict FieldTable::help() const {
  py::dict out;
  for (const auto& [path, field] : fields_) out[py::str(path)] = field.help;
  return out;
}

}  // namespace scanmatch::python
