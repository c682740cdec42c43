// libFuzzer target: CARMEN log text must be parsed or rejected with scanmatch::Error.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "scanmatch/core/error.hpp"
#include "scanmatch/io/carmen.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    scanmatch::parse_carmen_log(std::string_view(reinterpret_cast<const char*>(data), size),
                                "fuzz");
  } catch (const scanmatch::Error&) {
  }
  return 0;
}
