#include "scanmatch/io/lzf.hpp"

#include <cstdint>
#include <cstring>
#include <vector>

#include "scanmatch/core/error.hpp"

namespace scanmatch {
namespace {
// Format: a control byte c < 32 starts a literal run of c + 1 bytes; otherwise the top 3 bits are
// the match length - 2 (7 means "add the next byte"), the low 5 bits and the following byte the
// back-reference distance - 1 (13 bits, up to 8192).
constexpr std::size_t kMaxLiteral = 32;
constexpr std::size_t kMaxOffset = 1 << 13;
constexpr std::size_t kMaxMatch = (1 << 8) + (1 << 3);  // 264
constexpr int kHashBits = 14;

inline std::uint32_t hash3(const unsigned char* p) {
  const std::uint32_t v = (std::uint32_t{p[0]} << 16) | (std::uint32_t{p[1]} << 8) | p[2];
  return (v * 2654435761u) >> (32 - kHashBits);
}
}  // namespace

std::string lzf_compress(std::string_view input) {
  const auto* in = reinterpret_cast<const unsigned char*>(input.data());
  const std::size_t n = input.size();
  std::string out;
  out.reserve(n + n / kMaxLiteral + 16);
  std::vector<std::int64_t> last_seen(std::size_t{1} << kHashBits, -1);
  std::size_t literal_start = 0, i = 0;

  const auto flush_literals = [&](std::size_t end) {
    while (literal_start < end) {
      const std::size_t run = std::min(kMaxLiteral, end - literal_start);
      out.push_back(static_cast<char>(run - 1));
      out.append(reinterpret_cast<const char*>(in + literal_start), run);
      literal_start += run;
    }
  };

  while (i + 2 < n) {
    const std::uint32_t h = hash3(in + i);
    const std::int64_t candidate = last_seen[h];
    last_seen[h] = static_cast<std::int64_t>(i);
    if (candidate >= 0 && i - static_cast<std::size_t>(candidate) <= kMaxOffset &&
        std::memcmp(in + candidate, in + i, 3) == 0) {
      const std::size_t ref = static_cast<std::size_t>(candidate);
      std::size_t length = 3;
      while (length < kMaxMatch && i + length < n && in[ref + length] == in[i + length]) ++length;
      flush_literals(i);
      const std::size_t offset = i - ref - 1;
      const std::size_t code = length - 2;
      if (code < 7) {
        out.push_back(static_cast<char>((code << 5) | (offset >> 8)));
      } else {
        out.push_back(static_cast<char>((7 << 5) | (offset >> 8)));
        out.push_back(static_cast<char>(code - 7));
      }
      out.push_back(static_cast<char>(offset & 0xff));
      // Index the positions inside the match so later data can refer to them.
      for (std::size_t k = i + 1; k < i + length && k + 2 < n; ++k)
        last_seen[hash3(in + k)] = static_cast<std::int64_t>(k);
      i += length;
      literal_start = i;
    } else {
      ++i;
    }
  }
  flush_literals(n);
  return out;
}

std::string lzf_decompress(std::string_view input, std::size_t expected_size,
                           const std::string& source) {
  std::string out(expected_size, '\0');
  const auto* in = reinterpret_cast<const unsigned char*>(input.data());
  const std::size_t n = input.size();
  std::size_t ip = 0, op = 0;
  const auto corrupt = [&](const std::string& what) {
    fail(source, "compressed byte " + std::to_string(ip), "LZF data corrupt: " + what);
  };
  while (ip < n) {
    const std::size_t control = in[ip++];
    if (control < 32) {
      const std::size_t run = control + 1;
      if (ip + run > n) corrupt("literal run past the end of the input");
      if (op + run > expected_size) corrupt("output larger than the declared size");
      std::memcpy(out.data() + op, in + ip, run);
      ip += run;
      op += run;
    } else {
      std::size_t length = control >> 5;
      if (length == 7) {
        if (ip >= n) corrupt("truncated match length");
        length += in[ip++];
      }
      length += 2;
      if (ip >= n) corrupt("truncated back-reference");
      const std::size_t distance = ((control & 0x1f) << 8) + in[ip++] + 1;
      if (distance > op) corrupt("back-reference before the start of the output");
      if (op + length > expected_size) corrupt("output larger than the declared size");
      // Byte by byte: the source may overlap the destination (run-length style matches).
      for (std::size_t k = 0; k < length; ++k, ++op) out[op] = out[op - distance];
    }
  }
  if (op != expected_size)
    fail(source, "LZF data decompress to " + std::to_string(op) + " bytes, header declares " +
                     std::to_string(expected_size));
  return out;
}

}  // namespace scanmatch
