// Chunk decompression for the bag readers: bzip2 (ROS 1), LZ4 frames (ROS 1 and MCAP) and zstd
// (MCAP). The output grows as data arrives rather than trusting the declared size up front, so a
// forged size cannot make a small file allocate gigabytes.

#include <bzlib.h>
#include <lz4frame.h>
#include <zstd.h>

#include <algorithm>

#include "scanmatch/io/bag/bag_detail.hpp"

namespace scanmatch::bag_detail {
namespace {

/// Output buffer that doubles up to one byte past the declared size (to notice excess).
class Output {
 public:
  Output(std::uint64_t declared, std::size_t input_size)
      : limit_(declared + 1),
        buffer_(std::min<std::uint64_t>(limit_, std::max<std::uint64_t>(input_size * 4, 1 << 16)),
                '\0') {}
  /// Free space after the produced bytes; grows the buffer when full (empty at the limit).
  char* space(std::size_t& n) {
    if (produced_ == buffer_.size() && buffer_.size() < limit_)
      buffer_.resize(std::min<std::uint64_t>(limit_, buffer_.size() * 2));
    n = std::min<std::size_t>(buffer_.size() - produced_, std::size_t{1} << 30);
    return buffer_.data() + produced_;
  }
  void advance(std::size_t n) { produced_ += n; }
  bool full() const { return produced_ >= limit_; }
  std::size_t produced() const { return produced_; }
  std::string take() {
    buffer_.resize(produced_);
    return std::move(buffer_);
  }

 private:
  std::uint64_t limit_;
  std::string buffer_;
  std::size_t produced_ = 0;
};

std::string bunzip2(std::string_view in, Output& out, const std::string& source,
                    const std::string& where) {
  bz_stream s{};
  if (BZ2_bzDecompressInit(&s, 0, 0) != BZ_OK) fail(source, where, "cannot start bz2 decoding");
  s.next_in = const_cast<char*>(in.data());
  s.avail_in = static_cast<unsigned>(std::min<std::size_t>(in.size(), 0xffffffffu));
  int status = BZ_OK;
  while (status == BZ_OK && !out.full()) {
    std::size_t n = 0;
    s.next_out = out.space(n);
    s.avail_out = static_cast<unsigned>(n);
    status = BZ2_bzDecompress(&s);
    out.advance(n - s.avail_out);
    if (status == BZ_OK && s.avail_in == 0 && s.avail_out != 0) break;  // wants more input
  }
  BZ2_bzDecompressEnd(&s);
  if (status != BZ_OK && status != BZ_STREAM_END)
    fail(source, where, "bz2 data is corrupt (error " + std::to_string(status) + ")");
  if (status != BZ_STREAM_END && !out.full()) fail(source, where, "bz2 data is truncated");
  return out.take();
}

std::string unlz4(std::string_view in, Output& out, const std::string& source,
                  const std::string& where) {
  LZ4F_dctx* ctx = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION)))
    fail(source, where, "cannot start lz4 decoding");
  std::size_t consumed = 0, hint = 1;
  while (consumed < in.size() && !out.full()) {
    std::size_t n = 0;
    char* dst = out.space(n);
    std::size_t src_size = in.size() - consumed;
    hint = LZ4F_decompress(ctx, dst, &n, in.data() + consumed, &src_size, nullptr);
    if (LZ4F_isError(hint)) {
      const std::string message = LZ4F_getErrorName(hint);
      LZ4F_freeDecompressionContext(ctx);
      fail(source, where, "lz4 data is corrupt (" + message + ")");
    }
    consumed += src_size;
    out.advance(n);
    if (src_size == 0 && n == 0) break;  // no progress
  }
  LZ4F_freeDecompressionContext(ctx);
  if (hint != 0 && !out.full()) fail(source, where, "lz4 data is truncated");
  return out.take();
}

std::string unzstd(std::string_view in, Output& out, const std::string& source,
                   const std::string& where) {
  ZSTD_DCtx* ctx = ZSTD_createDCtx();
  if (!ctx) fail(source, where, "cannot start zstd decoding");
  ZSTD_inBuffer input{in.data(), in.size(), 0};
  std::size_t status = 1;
  while (input.pos < input.size && !out.full()) {
    std::size_t n = 0;
    ZSTD_outBuffer output{out.space(n), n, 0};
    status = ZSTD_decompressStream(ctx, &output, &input);
    if (ZSTD_isError(status)) {
      const std::string message = ZSTD_getErrorName(status);
      ZSTD_freeDCtx(ctx);
      fail(source, where, "zstd data is corrupt (" + message + ")");
    }
    out.advance(output.pos);
    if (output.pos == 0 && status != 0 && input.pos == input.size) break;
  }
  ZSTD_freeDCtx(ctx);
  if (status != 0 && !out.full()) fail(source, where, "zstd data is truncated");
  return out.take();
}

}  // namespace

std::string decompress(std::string_view compression, std::string_view data, std::uint64_t size,
                       const std::string& source, const std::string& where) {
  if (size > kMaxChunkBytes)
    fail(source, where,
         "chunk of " + std::to_string(size) + " bytes is larger than the 1 GiB limit");
  std::string out;
  if (compression.empty() || compression == "none") {
    out = std::string(data);
  } else {
    Output buffer(size, data.size());
    if (compression == "bz2")
      out = bunzip2(data, buffer, source, where);
    else if (compression == "lz4")
      out = unlz4(data, buffer, source, where);
    else if (compression == "zstd")
      out = unzstd(data, buffer, source, where);
    else
      fail(source, where,
           "unknown compression '" + std::string(compression.substr(0, 40)) +
               "' (known: none, bz2, lz4, zstd)");
  }
  if (out.size() != size)
    fail(source, where,
         (out.size() > size ? "decompressed data is larger than the declared "
                            : "decompressed data is smaller than the declared ") +
             std::to_string(size) + " bytes" +
             (out.size() > size ? "" : " (" + std::to_string(out.size()) + ")"));
  return out;
}

}  // namespace scanmatch::bag_detail
