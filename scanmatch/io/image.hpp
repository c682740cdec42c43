#pragma once
// Writers for 8-bit images: binary PGM (P5) and PNG (grayscale or RGB), encoded here with zlib;
// readers for binary PGM (a map2d run's map.pgm) and 8-bit PNG (e.g. a browser's screenshot,
// which tests inspect).
// Pixels are row-major with row 0 the top row of the image. Files are written atomically
// (write_file_atomic), so a reader never sees a half-written image.

#include <cstdint>
#include <string>
#include <vector>

namespace scanmatch {

/// Binary PGM (P5, maxval 255) of `width` x `height` grey levels. Throws Error naming the file
/// when a size is not positive, pixels.size() != width * height, or writing fails.
void write_pgm(const std::string& path, int width, int height,
               const std::vector<std::uint8_t>& pixels);

/// 8-bit grayscale PNG (colour type 0, no interlace, filter 0 on every row). Same contract and
/// errors as write_pgm.
void write_png(const std::string& path, int width, int height,
               const std::vector<std::uint8_t>& pixels);

/// 8-bit RGB PNG (colour type 2): `rgb` holds 3 bytes (red, green, blue) per pixel, so its size
/// must be 3 * width * height. Throws Error as write_png.
void write_png_rgb(const std::string& path, int width, int height,
                   const std::vector<std::uint8_t>& rgb);

/// An 8-bit image: `channels` bytes per pixel (1 grey, 2 grey + alpha, 3 RGB, 4 RGBA), row-major
/// with row 0 the top row.
struct Image8 {
  int width = 0, height = 0, channels = 0;
  std::vector<std::uint8_t> pixels;
};

/// Reads a binary PGM (P5, maxval 255; comments allowed in the header) as one channel. Throws
/// Error naming the file for anything else or fewer pixels than the header says.
Image8 read_pgm(const std::string& path);

/// Reads a non-interlaced 8-bit PNG of colour type 0, 2, 4 or 6 (any of the five row filters).
/// Throws Error naming the file for anything else or a damaged file.
Image8 read_png(const std::string& path);

}  // namespace scanmatch
