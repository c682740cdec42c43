#include "scanmatch/io/file_util.hpp"

#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "scanmatch/core/error.hpp"

namespace scanmatch {
namespace {

std::string inflate_gzip(const std::string& path, const std::string& compressed) {
  z_stream stream{};
  if (inflateInit2(&stream, 16 + MAX_WBITS) != Z_OK) fail(path, "cannot start gzip decompression");
  std::string out;
  out.resize(
      std::min<std::size_t>(std::max<std::size_t>(compressed.size() * 4, 1 << 16), kMaxInputBytes));
  stream.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(compressed.data()));
  stream.avail_in = static_cast<uInt>(compressed.size());
  std::size_t produced = 0;
  while (true) {
    if (produced == out.size()) {
      if (out.size() >= kMaxInputBytes) {
        inflateEnd(&stream);
        fail(path, "decompressed size exceeds the " + std::to_string(kMaxInputBytes >> 20) +
                       " MiB limit");
      }
      out.resize(std::min(out.size() * 2, kMaxInputBytes));
    }
    stream.next_out = reinterpret_cast<Bytef*>(out.data() + produced);
    stream.avail_out = static_cast<uInt>(std::min<std::size_t>(out.size() - produced, 1u << 30));
    const int status = inflate(&stream, Z_NO_FLUSH);
    produced = static_cast<std::size_t>(reinterpret_cast<char*>(stream.next_out) - out.data());
    if (status == Z_STREAM_END) {
      // Concatenated gzip members are legal: continue with the next one if input remains.
      if (stream.avail_in == 0) break;
      if (inflateReset(&stream) != Z_OK) break;
      continue;
    }
    if (status == Z_BUF_ERROR && stream.avail_in == 0) {
      inflateEnd(&stream);
      fail(path, "byte " + std::to_string(compressed.size()), "gzip data is truncated");
    }
    if (status != Z_OK && status != Z_BUF_ERROR) {
      const std::string message = stream.msg ? stream.msg : "corrupt data";
      const std::size_t offset = compressed.size() - stream.avail_in;
      inflateEnd(&stream);
      fail(path, "byte " + std::to_string(offset), "gzip: " + message);
    }
  }
  inflateEnd(&stream);
  out.resize(produced);
  return out;
}

}  // namespace

std::string read_file_bytes(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) fail(path, "is a folder, expected a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, std::string("cannot open: ") + std::strerror(errno));
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size < 0) fail(path, "cannot determine the file size");
  if (static_cast<std::size_t>(size) > kMaxInputBytes)
    fail(path, "file is larger than the input limit");
  in.seekg(0, std::ios::beg);
  std::string bytes(static_cast<std::size_t>(size), '\0');
  if (size > 0 && !in.read(bytes.data(), size)) fail(path, "read error");
  const bool gzip_magic = bytes.size() >= 2 && static_cast<unsigned char>(bytes[0]) == 0x1f &&
                          static_cast<unsigned char>(bytes[1]) == 0x8b;
  if (gzip_magic) return inflate_gzip(path, bytes);
  if (path.ends_with(".gz") && !bytes.empty())
    fail(path, "name ends in .gz but the data is not gzip");
  return bytes;
}

void write_file_atomic(const std::string& path, const std::string& bytes) {
  const std::filesystem::path target(path);
  const std::filesystem::path folder = target.has_parent_path() ? target.parent_path() : ".";
  std::error_code ec;
  if (!std::filesystem::is_directory(folder, ec))
    fail(path, "folder " + folder.string() + " does not exist");
  const std::string temporary = path + ".tmp." + std::to_string(::getpid());
  std::FILE* file = std::fopen(temporary.c_str(), "wb");
  if (!file) fail(path, std::string("cannot create: ") + std::strerror(errno));
  const bool written =
      bytes.empty() || std::fwrite(bytes.data(), 1, bytes.size(), file) == bytes.size();
  const bool flushed = std::fflush(file) == 0 && ::fsync(fileno(file)) == 0;
  const bool closed = std::fclose(file) == 0;
  if (!written || !flushed || !closed) {
    std::remove(temporary.c_str());
    fail(path, std::string("write failed: ") + std::strerror(errno));
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    std::remove(temporary.c_str());
    fail(path, "cannot rename the temporary file into place: " + reason);
  }
}

std::string extension_without_gz(const std::string& path) {
  std::string name = std::filesystem::path(path).filename().string();
  std::transform(name.begin(), name.end(), name.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  if (name.ends_with(".gz")) name.resize(name.size() - 3);
  const std::size_t dot = name.rfind('.');
  return dot == std::string::npos ? std::string() : name.substr(dot + 1);
}

}  // namespace scanmatch
