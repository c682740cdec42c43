// libFuzzer target: LZF decoding of arbitrary bytes, and compress/decompress round trips.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "scanmatch/core/error.hpp"
#include "scanmatch/io/lzf.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  try {
    scanmatch::lzf_decompress(input, size * 4, "fuzz");
  } catch (const scanmatch::Error&) {
  }
  const std::string packed = scanmatch::lzf_compress(input);
  if (scanmatch::lzf_decompress(packed, size, "fuzz") != input) std::abort();
  return 0;
}
