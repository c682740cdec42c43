#pragma once
// LZF compression (the format of liblzf, used by PCD's binary_compressed), our own codec.

#include <string>
#include <string_view>

namespace scanmatch {

/// Compresses `input`; the output may be slightly larger than the input for random data.
std::string lzf_compress(std::string_view input);

/// Decompresses into exactly `expected_size` bytes. Throws Error naming `source` and the byte
/// offset when the data are corrupt (back-reference before the start, output overrun, truncated
/// input, or a size that disagrees with `expected_size`).
std::string lzf_decompress(std::string_view input, std::size_t expected_size,
                           const std::string& source);

}  // namespace scanmatch
