#include "scanmatch/io/cloud_io.hpp"

#include <cctype>
#include <cstdio>
#include <cstring>
#include <optional>

#include "scanmatch/io/file_util.hpp"
#include "scanmatch/io/parse_util.hpp"
#include "scanmatch/io/pcd.hpp"
#include "scanmatch/io/ply.hpp"

namespace scanmatch {
namespace {
using namespace io_detail;

PointCloud parse_kitti_bin(std::string_view bytes, const std::string& source,
                           const CloudReadOptions& options, CloudFileInfo* info) {
  if (bytes.empty()) fail(source, "file is empty");
  if (bytes.size() % 16 != 0)
    fail(source, "size " + std::to_string(bytes.size()) +
                     " bytes is not a multiple of 16 (float32 x y z intensity per point): "
                     "truncated or not a KITTI .bin");
  const std::size_t n = bytes.size() / 16;
  if (info) {
    info->format = CloudFormat::kKittiBin;
    info->encoding = "binary";
    info->fields = {"x", "y", "z", "intensity"};
    info->width = n;
    info->height = 1;
  }
  CloudBuilder builder(true, false, false, options);
  builder.reserve(n);
  double values[6] = {0, 0, 0, 0, 0, 0};
  for (std::size_t i = 0; i < n; ++i) {
    float v[4];
    std::memcpy(v, bytes.data() + 16 * i, 16);
    for (int k = 0; k < 4; ++k) values[k] = v[k];
    builder.add(values);
  }
  return builder.finish(info);
}

PointCloud parse_text(std::string_view bytes, const std::string& source,
                      const CloudReadOptions& options, CloudFileInfo* info) {
  LineCursor cursor(bytes);
  std::string_view line;
  std::vector<std::string_view> tokens;
  std::vector<FieldRole> columns;
  std::vector<std::string> names;
  bool layout_known = false;
  bool has[6] = {false, false, false, false, false, false};
  std::optional<CloudBuilder> builder;
  double values[6] = {0, 0, 0, 0, 0, 0};
  const auto set_layout = [&](std::vector<FieldRole> roles) {
    columns = std::move(roles);
    for (FieldRole r : columns)
      if (r != FieldRole::kIgnore) has[static_cast<int>(r)] = true;
    builder.emplace(has[3], has[4], has[5], options);
    layout_known = true;
  };
  while (cursor.next(line)) {
    const std::string where = "line " + std::to_string(cursor.line_number());
    const std::string_view content = trim(line);
    if (content.empty() || content.front() == '#' || content.substr(0, 2) == "//") continue;
    split_tokens(content, tokens);
    if (tokens.empty()) continue;  // only separators
    if (!layout_known) {
      double probe;
      if (!parse_double(tokens[0], probe)) {
        // A header of column names.
        std::vector<FieldRole> roles;
        for (auto t : tokens) {
          std::string name(t);
          for (auto& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
          if (name.size() >= 2 && name.front() == '"' && name.back() == '"')
            name = name.substr(1, name.size() - 2);
          names.push_back(name);
          roles.push_back(field_role(name));
        }
        set_layout(std::move(roles));
        if (!has[0] || !has[1] || !has[2])
          fail(source, where, "header has no x, y and z columns: " + quoted(content));
        continue;
      }
      if (tokens.size() < 3)
        fail(source, where,
             "expected at least 3 columns (x y z), found " + std::to_string(tokens.size()));
      std::vector<FieldRole> roles = {FieldRole::kX, FieldRole::kY, FieldRole::kZ};
      names = {"x", "y", "z"};
      if (tokens.size() >= 4) {
        roles.push_back(FieldRole::kIntensity);
        names.push_back("intensity");
      }
      for (std::size_t k = roles.size(); k < tokens.size(); ++k) {
        roles.push_back(FieldRole::kIgnore);
        names.push_back("column" + std::to_string(k + 1));
      }
      set_layout(std::move(roles));
    }
    if (tokens.size() != columns.size())
      fail(source, where,
           "expected " + std::to_string(columns.size()) + " columns, found " +
               std::to_string(tokens.size()));
    for (std::size_t k = 0; k < tokens.size(); ++k) {
      double v;
      if (!parse_double(tokens[k], v)) fail(source, where, "not a number: " + quoted(tokens[k]));
      if (columns[k] != FieldRole::kIgnore) values[static_cast<int>(columns[k])] = v;
    }
    builder->add(values);
  }
  if (!builder || builder->points_in_file() == 0) fail(source, "no points in the file");
  if (info) {
    info->format = CloudFormat::kText;
    info->encoding = "ascii";
    info->fields = names;
    info->width = builder->points_in_file();
    info->height = 1;
  }
  return builder->finish(info);
}

std::string format_text(const PointCloud& cloud, bool csv) {
  const char* sep = csv ? "," : " ";
  std::string out;
  out += std::string("x") + sep + "y" + sep + "z";
  if (cloud.has_intensity()) {
    out += sep;
    out += "intensity";
  }
  if (cloud.has_ring()) {
    out += sep;
    out += "ring";
  }
  if (cloud.has_time()) {
    out += sep;
    out += "t";
  }
  out += '\n';
  for (std::size_t i = 0; i < cloud.size(); ++i) append_point_text(out, cloud, i, csv ? ',' : ' ');
  return out;
}

}  // namespace

CloudFormat cloud_format_from_path(const std::string& path) {
  const std::string ext = extension_without_gz(path);
  if (ext == "pcd") return CloudFormat::kPcd;
  if (ext == "ply") return CloudFormat::kPly;
  if (ext == "bin") return CloudFormat::kKittiBin;
  if (ext == "xyz" || ext == "txt" || ext == "csv") return CloudFormat::kText;
  fail(path, "unknown point cloud format '." + ext +
                 "' (expected .pcd, .ply, .bin, .xyz, .txt or .csv, optionally .gz)");
}

const char* to_string(CloudFormat format) {
  switch (format) {
    case CloudFormat::kPcd:
      return "PCD";
    case CloudFormat::kPly:
      return "PLY";
    case CloudFormat::kKittiBin:
      return "KITTI bin";
    case CloudFormat::kText:
      return "text";
  }
  return "?";
}

PointCloud parse_cloud(std::string_view bytes, CloudFormat format, const std::string& source,
                       const CloudReadOptions& options, CloudFileInfo* info) {
  switch (format) {
    case CloudFormat::kPcd:
      return parse_pcd(bytes, source, options, info);
    case CloudFormat::kPly:
      return parse_ply(bytes, source, options, info);
    case CloudFormat::kKittiBin:
      return parse_kitti_bin(bytes, source, options, info);
    case CloudFormat::kText:
      return parse_text(bytes, source, options, info);
  }
  fail(source, "unknown format");
}

PointCloud read_cloud(const std::string& path, const CloudReadOptions& options,
                      CloudFileInfo* info) {
  const CloudFormat format = cloud_format_from_path(path);
  const std::string bytes = read_file_bytes(path);
  CloudFileInfo local;
  CloudFileInfo* out = info ? info : &local;
  PointCloud cloud = parse_cloud(bytes, format, path, options, out);
  out->compressed_gzip = path.size() > 3 && path.substr(path.size() - 3) == ".gz";
  return cloud;
}

void write_cloud(const std::string& path, const PointCloud& cloud,
                 const CloudWriteOptions& options) {
  if (!cloud.fields_consistent())
    fail(path, "cannot write: the cloud's fields and points differ in length");
  const CloudFormat format = cloud_format_from_path(path);
  if (path.size() > 3 && path.substr(path.size() - 3) == ".gz")
    fail(path, "writing gzip-compressed clouds is not supported; write the plain file and gzip it");
  std::string bytes;
  switch (format) {
    case CloudFormat::kPcd:
      bytes = format_pcd(cloud, options.encoding);
      break;
    case CloudFormat::kPly:
      bytes = format_ply(cloud, options.encoding);
      break;
    case CloudFormat::kKittiBin:
      bytes.reserve(cloud.size() * 16);
      for (std::size_t i = 0; i < cloud.size(); ++i) {
        const float v[4] = {cloud.points[i].x(), cloud.points[i].y(), cloud.points[i].z(),
                            cloud.has_intensity() ? cloud.intensity[i] : 0.0f};
        append_bytes(bytes, v, 16);
      }
      break;
    case CloudFormat::kText:
      bytes = format_text(cloud, extension_without_gz(path) == "csv");
      break;
  }
  write_file_atomic(path, bytes);
}

}  // namespace scanmatch
