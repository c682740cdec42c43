#include "scanmatch/core/error.hpp"

namespace scanmatch {

void fail(const std::string& source, const std::string& where, const std::string& problem) {
  if (where.empty()) throw Error(source + ": " + problem);
  throw Error(source + ": " + where + ": " + problem);
}

void fail(const std::string& source, const std::string& problem) {
  fail(source, "", problem);
}

}  // namespace scanmatch
