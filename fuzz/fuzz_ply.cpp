// libFuzzer target: the ply reader must reject any input with scanmatch::Error, never crash.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "scanmatch/core/error.hpp"
#include "scanmatch/io/cloud_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    scanmatch::parse_cloud(std::string_view(reinterpret_cast<const char*>(data), size),
                           scanmatch::CloudFormat::kPly, "fuzz");
  } catch (const scanmatch::Error&) {
  }
  return 0;
}
