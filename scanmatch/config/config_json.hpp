#pragma once
// Reading and writing any described configuration (config/fields.hpp) as JSON: keys are the field
// names, nested options nested objects; a file may give any subset; unknown keys and wrong types
// are errors naming the file and the key. For the .cpp files that define a module's or a run's
// config I/O (config_io.cpp, run/run_config.cpp); it pulls in nlohmann/json.

#include <functional>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <type_traits>

#include "scanmatch/core/error.hpp"

namespace scanmatch::config_json {

using Json = nlohmann::ordered_json;

struct ToJson {
  Json& j;
  template <typename T>
  void operator()(const char* key, T& field, const char*, const char*) {
    if constexpr (std::is_enum_v<T>)
      j[key] = enum_name(field);
    else
      j[key] = field;
  }
  template <typename S>
  void nested(const char* key, S& options) {
    Json sub = Json::object();
    ToJson inner{sub};
    describe(options, inner);
    j[key] = sub;
  }
};

// Only the fields whose flag was given on the command line.
struct GivenToJson {
  Json& j;
  const std::function<bool(const std::string&)>& was_given;
  template <typename T>
  void operator()(const char* key, T& field, const char* flag, const char* help) {
    if (flag && was_given(flag)) ToJson{j}(key, field, flag, help);
  }
  template <typename S>
  void nested(const char* key, S& options) {
    Json sub = Json::object();
    GivenToJson inner{sub, was_given};
    describe(options, inner);
    if (!sub.empty()) j[key] = sub;
  }
};

// The keys a description knows (fields and nested objects), for the unknown-key check.
struct KeyNames {
  std::set<std::string> names;
  template <typename T>
  void operator()(const char* key, T&, const char*, const char*) {
    names.insert(key);
  }
  template <typename S>
  void nested(const char* key, S&) {
    names.insert(key);
  }
};

struct FromJson {
  const Json& j;
  const std::string& source;
  std::string path;  ///< "registration.solver." for errors

  template <typename T>
  void operator()(const char* key, T& field, const char*, const char*) {
    if (!j.contains(key)) return;
    const Json& value = j[key];
    try {
      if constexpr (std::is_enum_v<T>) {
        if (!value.is_string()) throw std::invalid_argument("");
        enum_from_name(value.get<std::string>(), field);
        return;
      } else if constexpr (std::is_same_v<T, bool>) {
        if (!value.is_boolean()) throw std::invalid_argument("");
      } else if constexpr (std::is_same_v<T, std::string>) {
        if (!value.is_string()) throw std::invalid_argument("");
      } else {
        if (!value.is_number()) throw std::invalid_argument("");
        if constexpr (std::is_unsigned_v<T>)
          if (value.template get<double>() < 0) throw std::invalid_argument("");
      }
      field = value.template get<T>();
    } catch (const Error& e) {
      fail(source, "key '" + path + key + "': " + e.what());
    } catch (const std::exception&) {
      fail(source, "key '" + path + key + "' has the wrong type or value (" + value.dump() + ")");
    }
  }
  template <typename S>
  void nested(const char* key, S& options) {
    if (j.contains(key)) read(j[key], options, source, path + key + ".");
  }

  template <typename S>
  static void read(const Json& j, S& options, const std::string& source, const std::string& path) {
    if (!j.is_object())
      fail(source, path.empty() ? "expected a JSON object" : path + ": expected an object");
    KeyNames keys;
    describe(options, keys);
    for (const auto& item : j.items())
      if (!keys.names.count(item.key())) fail(source, "unknown key '" + path + item.key() + "'");
    FromJson reader{j, source, path};
    describe(options, reader);
  }
};

inline Json parse(const std::string& text, const std::string& source) {
  try {
    return Json::parse(text);
  } catch (const Json::parse_error& e) {
    fail(source, std::string("not valid JSON: ") + e.what());
  }
}

template <typename Config>
std::string config_to_json(const Config& config) {
  Config c = config;
  Json j = Json::object();
  ToJson writer{j};
  describe(c, writer);
  return j.dump(2) + "\n";
}

template <typename Config>
Config config_from_json(const std::string& text, const std::string& source, const Config& base) {
  Config c = base;
  FromJson::read(parse(text, source), c, source, "");
  return c;
}

template <typename Config>
Config config_override_given(const Config& base, const Config& given,
                             const std::function<bool(const std::string&)>& was_given) {
  Config g = given;
  Json j = Json::object();
  GivenToJson writer{j, was_given};
  describe(g, writer);
  Config c = base;
  FromJson::read(j, c, "the command line", "");
  return c;
}

}  // namespace scanmatch::config_json
