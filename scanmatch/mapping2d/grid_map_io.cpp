// OccupancyGrid's outputs: the ROS map_server pair (PGM + YAML) and a PNG.

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>

#include "scanmatch/core/error.hpp"
#include "scanmatch/io/file_util.hpp"
#include "scanmatch/io/image.hpp"
#include "scanmatch/mapping2d/grid_map.hpp"

namespace scanmatch {
namespace {

// Shortest text that reads back as the same (finite) double, with a decimal point so that YAML
// 1.1 reads a float ("2.0", "1.0e-07").
std::string yaml_number(double value) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  std::string text(buffer, result.ptr);
  if (text.find('.') == std::string::npos) text.insert(std::min(text.find('e'), text.size()), ".0");
  return text;
}

// A YAML scalar for a file name: plain when safe, double-quoted otherwise.
std::string yaml_string(const std::string& text) {
  const bool plain = !text.empty() && std::all_of(text.begin(), text.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-';
  });
  if (plain) return text;
  std::string quoted = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') quoted += '\\';
    quoted += c;
  }
  return quoted + "\"";
}

}  // namespace

std::vector<std::uint8_t> OccupancyGrid::render() const {
  std::vector<std::uint8_t> pixels(log_odds_.size(), kUnknownPixel);
  for (int row = 0; row < height_; ++row) {
    // Image rows run from the top (highest y) down; grid rows from the lowest y up.
    const std::size_t image_row = static_cast<std::size_t>(height_ - 1 - row);
    for (int column = 0; column < width_; ++column) {
      const float log_odds = log_odds_[static_cast<std::size_t>(row) * width_ + column];
      if (std::isnan(log_odds)) continue;
      const double p = log_odds_to_probability(log_odds);
      std::uint8_t& pixel = pixels[image_row * width_ + column];
      if (p > options_.occupied_threshold)
        pixel = kOccupiedPixel;
      else if (p < options_.free_threshold)
        pixel = kFreePixel;
    }
  }
  return pixels;
}

void OccupancyGrid::write_map_server(const std::string& pgm_or_base_path) const {
  std::string base = pgm_or_base_path;
  for (const char* extension : {".pgm", ".yaml"})
    if (base.ends_with(extension)) base.resize(base.size() - std::string(extension).size());
  const std::string pgm_path = base + ".pgm";
  const std::string yaml_path = base + ".yaml";
  if (log_odds_.empty()) fail(pgm_path, "the occupancy grid is empty: no scan was inserted");

  // The image first: a YAML that exists always names a complete image.
  write_pgm(pgm_path, width_, height_, render());
  const Eigen::Vector2d lower_left = origin();
  const std::string yaml =
      "image: " + yaml_string(std::filesystem::path(pgm_path).filename().string()) + "\n" +
      "resolution: " + yaml_number(options_.resolution) + "\n" + "origin: [" +
      yaml_number(lower_left.x()) + ", " + yaml_number(lower_left.y()) + ", 0.0]\n" +
      "negate: 0\n" + "occupied_thresh: " + yaml_number(options_.occupied_threshold) + "\n" +
      "free_thresh: " + yaml_number(options_.free_threshold) + "\n" + "mode: trinary\n";
  write_file_atomic(yaml_path, yaml);
}

void OccupancyGrid::write_png(const std::string& path) const {
  if (log_odds_.empty()) fail(path, "the occupancy grid is empty: no scan was inserted");
  scanmatch::write_png(path, width_, height_, render());
}

}  // namespace scanmatch
