#pragma once
// Errors: every failure that reaches a user names the file (or input) and the problem.

#include <stdexcept>
#include <string>

namespace scanmatch {

/// The one exception type of the library. `what()` is a complete, user-facing, one-line message.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Throws Error("<source>: <where>: <problem>"); `where` may be empty (e.g. "line 12", "byte
/// 4096").
[[noreturn]] void fail(const std::string& source, const std::string& where,
                       const std::string& problem);

/// Throws Error("<source>: <problem>").
[[noreturn]] void fail(const std::string& source, const std::string& problem);

}  // namespace scanmatch
