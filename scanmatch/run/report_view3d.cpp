#include "scanmatch/run/report_view3d.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "scanmatch/core/error.hpp"
#include "scanmatch/eval/metrics.hpp"
#include "scanmatch/eval/svg_plot.hpp"
#include "scanmatch/geometry/voxel_filter.hpp"
#include "scanmatch/geometry/voxel_key.hpp"
#include "scanmatch/io/cloud_io.hpp"
#include "scanmatch/io/file_util.hpp"
#include "scanmatch/io/image.hpp"
#include "scanmatch/odometry/health.hpp"
#include "scanmatch/run/report.hpp"

namespace scanmatch {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// Voxels a cloud occupies at edge `size` (non-finite points skipped): its voxel keys sorted and
// counted once each (a sort is several times faster here than a hash set of as many keys).
std::size_t occupied_voxels(const PointCloud& cloud, double size) {
  std::vector<std::uint64_t> keys;
  keys.reserve(cloud.size());
  const float inverse = static_cast<float>(1.0 / size);
  for (const Point& p : cloud.points) {
    if (!p.allFinite()) continue;
    const VoxelKey k = voxel_key_scaled(Eigen::Vector3f(p * inverse));
    // 21 bits per axis: a collision only merges two voxels' counts, never a point.
    keys.push_back((static_cast<std::uint64_t>(k.x & 0x1fffff) << 42) |
                   (static_cast<std::uint64_t>(k.y & 0x1fffff) << 21) |
                   static_cast<std::uint64_t>(k.z & 0x1fffff));
  }
  std::sort(keys.begin(), keys.end());
  return static_cast<std::size_t>(std::unique(keys.begin(), keys.end()) - keys.begin());
}

// Every n-th point so that exactly `count` remain (count < cloud.size()).
PointCloud pick_evenly(const PointCloud& cloud, std::size_t count) {
  PointCloud out;
  out.points.reserve(count);
  for (std::size_t k = 0; k < count; ++k) {
    const std::size_t at = k * cloud.size() / count;
    out.points.push_back(cloud.points[at]);
    if (cloud.has_intensity()) out.intensity.push_back(cloud.intensity[at]);
  }
  return out;
}

PointCloud positions_and_intensity(PointCloud cloud) {
  cloud.ring.clear();
  cloud.time.clear();
  return cloud;
}

// Little-endian bytes of a trivially copyable value.
template <typename T>
void append_le(std::string& out, T value) {
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) std::reverse(bytes, bytes + sizeof(T));
  out.append(reinterpret_cast<const char*>(bytes), sizeof(T));
}

double rounded(double value, double unit) {
  return std::round(value / unit) * unit;
}

// x, y, z of every pose, to the millimetre.
json positions(const std::vector<Pose>& poses) {
  json xyz = json::array();
  for (const Pose& p : poses)
    for (int axis = 0; axis < 3; ++axis) xyz.push_back(rounded(p.translation()[axis], 1e-3));
  return xyz;
}

// The map for the page: positions quantized to 16 bits within the bounding box, intensities to
// 8 bits between their 2nd and 98th percentiles; both base64.
json encode_map(const PointCloud& cloud, const std::string& description,
                std::size_t source_points) {
  Eigen::AlignedBox3f box;
  for (const Point& p : cloud.points) box.extend(p);
  const Eigen::Vector3f center = box.center();
  const Eigen::Vector3f half = (box.sizes() / 2).cwiseMax(1e-3f);
  std::string xyz;
  xyz.reserve(cloud.size() * 6);
  for (const Point& p : cloud.points)
    for (int axis = 0; axis < 3; ++axis)
      append_le(xyz, static_cast<std::int16_t>(
                         std::lround((p[axis] - center[axis]) / half[axis] * 32767.0f)));
  json map = {{"count", cloud.size()},
              {"center", {center.x(), center.y(), center.z()}},
              {"half", {half.x(), half.y(), half.z()}},
              {"xyz", base64_encode(xyz)},
              {"intensity", nullptr},
              {"description", description},
              {"source_points", source_points}};
  if (cloud.has_intensity() && !cloud.empty()) {
    std::vector<float> sorted = cloud.intensity;
    std::sort(sorted.begin(), sorted.end());
    const float low = sorted[sorted.size() * 2 / 100], high = sorted[sorted.size() * 98 / 100];
    if (high > low) {
      std::string levels;
      levels.reserve(cloud.size());
      for (const float v : cloud.intensity)
        levels.push_back(static_cast<char>(
            std::lround(std::clamp((v - low) / (high - low), 0.0f, 1.0f) * 255.0f)));
      map["intensity"] = base64_encode(levels);
      map["intensity_range"] = {low, high};
    }
  }
  return map;
}

// A map2d occupancy grid (map.pgm and map.yaml, map_server's format) as grey levels with row 0
// the lowest y, shrunk by an integer factor (keeping each block's darkest cell, so walls stay)
// to at most 4096 cells a side, the texture size every WebGL has.
json encode_grid(const std::string& folder) {
  const std::string pgm_path = folder + "/map.pgm", yaml_path = folder + "/map.yaml";
  const Image8 image = read_pgm(pgm_path);
  const int width = image.width, height = image.height;

  double resolution = 0, origin_x = 0, origin_y = 0;
  bool has_resolution = false, has_origin = false;
  std::istringstream yaml(read_file_bytes(yaml_path));
  for (std::string line; std::getline(yaml, line);) {
    if (line.rfind("resolution:", 0) == 0) {
      has_resolution = std::sscanf(line.c_str(), "resolution: %lf", &resolution) == 1;
    } else if (line.rfind("origin:", 0) == 0) {
      has_origin = std::sscanf(line.c_str(), "origin: [%lf, %lf", &origin_x, &origin_y) == 2;
    }
  }
  if (!has_resolution || !(resolution > 0) || !has_origin)
    fail(yaml_path, "no positive resolution or no origin [x, y, yaw]");

  const int factor = std::max(1, (std::max(width, height) + 4095) / 4096);
  const int cols = (width + factor - 1) / factor, rows = (height + factor - 1) / factor;
  std::string levels(static_cast<std::size_t>(cols) * rows, '\xff');
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const int row = (height - 1 - y) / factor;  // image row 0 is the top, the highest y
      char& cell = levels[static_cast<std::size_t>(row) * cols + x / factor];
      const char pixel = static_cast<char>(image.pixels[static_cast<std::size_t>(y) * width + x]);
      if (static_cast<unsigned char>(pixel) < static_cast<unsigned char>(cell)) cell = pixel;
    }
  return {{"width", cols},
          {"height", rows},
          {"cell", resolution * factor},
          {"origin", {origin_x, origin_y}},
          {"pixels", base64_encode(levels)}};
}

// Per frame of `run`: the error of the step to it against the reference (null where none pairs).
std::pair<json, json> step_errors(const RunFolder& run, const std::optional<Trajectory>& gt) {
  json m(run.poses.size(), nullptr), deg(run.poses.size(), nullptr);
  if (!gt) return {m, deg};
  const Association pairs = associate(*gt, run.poses, /*allow_partial=*/true);
  if (pairs.estimate.size() < 2) return {m, deg};
  const RelativeErrors e = relative_errors(pairs.ground_truth, pairs.estimate, 1);
  for (std::size_t k = 0; k < e.translation.size(); ++k) {
    const std::size_t frame = pairs.estimate_index[k + 1];
    m[frame] = rounded(e.translation[k], 1e-4);
    deg[frame] = rounded(e.rotation[k], 1e-3);
  }
  return {m, deg};
}

std::string three_js_folder(const View3DOptions& options) {
  if (!options.three_js_dir.empty()) return options.three_js_dir;
  if (const char* env = std::getenv("SCANMATCH_THREE_JS_DIR"); env && *env) return env;
  return kDefaultThreeJsDir;
}

// JSON inside <script>: "</" could close the element early.
std::string script_safe(std::string text) {
  for (auto at = text.find("</"); at != std::string::npos; at = text.find("</", at + 3))
    text.replace(at, 2, "<\\/");
  return text;
}

const char* kView3DStyle =
    "<style>#view3d-box{border:1px solid #ccc;background:#fafafa;margin:8px 0 20px}"
    "#view3d-bar{padding:6px 8px;display:flex;flex-wrap:wrap;gap:6px 14px;align-items:center;"
    "font-size:14px}#view3d-bar button{padding:2px 8px}"
    "#view3d-canvas{position:relative;height:640px;background:#15171c;overflow:hidden}"
    "#view3d-tip{position:absolute;pointer-events:none;background:rgba(255,255,255,.92);"
    "color:#111;padding:4px 8px;border-radius:4px;font-size:13px;display:none;"
    "white-space:pre;z-index:2}#view3d-legend{position:absolute;left:8px;bottom:8px;"
    "color:#eee;font-size:12px;z-index:2;pointer-events:none;background:rgba(20,22,28,.7);"
    "padding:3px 6px;border-radius:3px}"
    "body.view3d-only{margin:0;max-width:none}body.view3d-only>*{display:none}"
    "body.view3d-only>#view3d-box{display:block;margin:0;border:0}"
    "body.view3d-only #view3d-note{display:none}"
    "#view3d-status{display:none}</style>\n";

// Paths in colours the height ramp (blue to red) of the map does not use, and that show on the
// white free space of a 2D grid too.
const char* const kPathColors[] = {"#ff40ff", "#ffb000", "#00e5ff", "#9dff3c", "#ff7f7f"};

}  // namespace

std::string base64_encode(const std::string& bytes) {
  static const char* const kAlphabet =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t k = 0;
  for (; k + 2 < bytes.size(); k += 3) {
    const std::uint32_t v = (static_cast<std::uint8_t>(bytes[k]) << 16) |
                            (static_cast<std::uint8_t>(bytes[k + 1]) << 8) |
                            static_cast<std::uint8_t>(bytes[k + 2]);
    out += kAlphabet[v >> 18];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += kAlphabet[v & 63];
  }
  if (k < bytes.size()) {
    const bool two = k + 1 < bytes.size();
    const std::uint32_t v = (static_cast<std::uint8_t>(bytes[k]) << 16) |
                            (two ? static_cast<std::uint8_t>(bytes[k + 1]) << 8 : 0);
    out += kAlphabet[v >> 18];
    out += kAlphabet[(v >> 12) & 63];
    out += two ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

PointCloud downsample_to_budget(const PointCloud& cloud, std::size_t max_points) {
  if (max_points == 0) throw Error("downsample_to_budget: a budget of 0 points");
  // The page's 16-bit positions need a finite bounding box.
  PointCloud finite = positions_and_intensity(cloud);
  remove_non_finite(finite);
  if (finite.size() <= max_points) return finite;
  const std::size_t slack = max_points + max_points * 3 / 10;
  // The smallest edge within a factor 1.19 whose voxels fit the slack: doubling from 2 cm until
  // they fit, then halving the last factor of two (in log scale) three times.
  double size = 0.02;
  if (occupied_voxels(finite, size) > slack) {
    double too_small = size;
    size *= 2;
    while (occupied_voxels(finite, size) > slack) too_small = size, size *= 2;
    for (int step = 0; step < 3; ++step) {
      const double middle = std::sqrt(too_small * size);
      (occupied_voxels(finite, middle) > slack ? too_small : size) = middle;
    }
  }
  PointCloud voxels =
      positions_and_intensity(voxel_downsample(finite, size, VoxelReduction::kNearestToCentroid));
  return voxels.size() <= max_points ? voxels : pick_evenly(voxels, max_points);
}

PointCloud rebuild_map_from_frames(const RunFolder& run, const std::string& spec,
                                   const SequenceOptions& sequence, std::size_t max_points) {
  const Trajectory& poses = run.optimized ? *run.optimized : run.poses;
  SequenceOptions options = sequence;
  if (is_simulator_spec(spec)) options.simulator.frames = poses.size();
  const auto source = open_sequence(spec, options);
  if (source->size() < poses.size())
    fail(spec, fmt::format("{} frames, but run {} has {} poses: not the sequence it read",
                           source->size(), run.path, poses.size()));
  PointCloud map;
  double voxel = 0.02;
  bool intensity = true;
  Frame frame;
  for (std::size_t k = 0; k < poses.size() && source->next(frame); ++k) {
    if (poses.has_timestamps() && std::abs(frame.timestamp - poses.timestamps[k]) > 0.05)
      fail(spec, fmt::format("frame {} ({}) is at {:.3f} s, but run {} has its pose {} at {:.3f} "
                             "s: not the sequence it read",
                             k, frame.name, frame.timestamp, run.path, k, poses.timestamps[k]));
    intensity = intensity && frame.cloud.has_intensity();
    if (!intensity) map.intensity.clear();
    const Eigen::Isometry3f pose = poses.poses[k].cast<float>();
    PointCloud placed = voxel_downsample(positions_and_intensity(frame.cloud), voxel);
    for (std::size_t i = 0; i < placed.size(); ++i) {
      map.points.push_back(pose * placed.points[i]);
      if (intensity) map.intensity.push_back(placed.intensity[i]);
    }
    // Thin out as the map grows: memory stays within a few budgets whatever the sequence length.
    if (map.size() > 4 * max_points) {
      map = voxel_downsample(map, voxel);
      while (map.size() > 2 * max_points) map = voxel_downsample(map, voxel *= 1.5);
    }
  }
  return downsample_to_budget(map, max_points);
}

std::string render_view3d(const std::vector<RunFolder>& runs,
                          const std::optional<Trajectory>& ground_truth,
                          const View3DOptions& options) {
  std::string html =
      "<h2 id=\"view3d\">3D view</h2>\n" + std::string(kView3DStyle) +
      "<div id=\"view3d-box\"><div id=\"view3d-bar\"></div><div id=\"view3d-canvas\">"
      "<div id=\"view3d-tip\"></div><div id=\"view3d-legend\"></div></div>"
      "<p id=\"view3d-note\" style=\"margin:6px 8px\">";
  const std::string folder = three_js_folder(options);
  const std::string three_path = folder + "/three.min.js";
  const std::string controls_path = folder + "/examples/js/controls/OrbitControls.js";
  if (!fs::is_regular_file(three_path) || !fs::is_regular_file(controls_path)) {
    return html +
           "The 3D view needs three.js (the Debian package libjs-three: three.min.js and "
           "examples/js/controls/OrbitControls.js), which was not found in " +
           html_escape(folder) +
           " when this report was made; the 2D views below show the same runs.</p></div>\n"
           "<pre id=\"view3d-status\">{\"three\":false}</pre>\n";
  }

  json data = {
      {"runs", json::array()}, {"reference", nullptr}, {"map", nullptr}, {"grid", nullptr}};
  std::string note;
  bool reference_drawn = false;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const RunFolder& run = runs[i];
    const std::optional<Trajectory>& gt = ground_truth ? ground_truth : run.ground_truth;
    // Where the map sits: the loop-closed poses when there are, else the odometry's.
    const std::vector<Pose>& main = run.optimized ? run.optimized->poses : run.poses.poses;
    json yaw = json::array();
    for (const Pose& p : main)
      yaw.push_back(rounded(std::atan2(p.linear()(1, 0), p.linear()(0, 0)), 1e-3));
    // Every flag shows on hover; frames whose pose the record says not to trust (bridged, thin
    // map, stages disagree) are marked, the others (an uncertain prior, a recovery: on every
    // keyframe of a hand-held Livox) on a layer of their own.
    json flags = json::object(), marked = json::array(), noted = json::array();
    for (const FrameRecord& r : run.timing) {
      const std::string text = frame_health_flags(r.stats);
      if (text.empty() || r.index >= main.size()) continue;
      flags[std::to_string(r.index)] = text;
      const FrameStats& f = r.stats;
      (f.bridged || health::thin_map(f) || health::stages_disagree(f) ? marked : noted)
          .push_back(r.index);
    }
    json loops = json::array();
    for (const auto& [from, to] : run.loops)
      if (from < main.size() && to < main.size()) loops.push_back({from, to});
    auto [step_m, step_deg] = step_errors(run, gt);
    data["runs"].push_back({{"label", run.label},
                            {"method", run.method},
                            {"color", kPathColors[i % std::size(kPathColors)]},
                            {"odometry", positions(run.poses.poses)},
                            {"optimized", run.optimized ? positions(main) : json(nullptr)},
                            {"yaw", yaw},
                            {"loops", loops},
                            {"flags", flags},
                            {"marked", marked},
                            {"noted", noted},
                            {"step_m", step_m},
                            {"step_deg", step_deg}});
    if (gt && !reference_drawn) {
      const Association pairs = associate(*gt, run.poses, /*allow_partial=*/true);
      data["reference"] = positions(pairs.ground_truth);
      reference_drawn = true;
    }
  }

  // The map: rebuilt from frames when they are given (the saved map has no intensities), else
  // the first saved one; a map2d run's grid.
  for (const RunFolder& run : options.frames.empty() ? runs : std::vector<RunFolder>{}) {
    for (const char* name : {"map.pcd", "map.ply"}) {
      const std::string path = run.path + "/" + name;
      if (!fs::is_regular_file(path)) continue;
      const PointCloud saved = read_cloud(path);
      const PointCloud shown = downsample_to_budget(saved, options.max_points);
      data["map"] = encode_map(shown, fmt::format("{} of {}", name, run.label), saved.size());
      note = fmt::format(
          "Map: {} of run {}, {} points{}.", name, html_escape(run.label), saved.size(),
          shown.size() < saved.size()
              ? fmt::format(", {} of them shown (budget {})", shown.size(), options.max_points)
              : "");
      break;
    }
    if (!data["map"].is_null()) break;
  }
  if (!options.frames.empty()) {
    const RunFolder& run = runs.front();
    const PointCloud shown =
        rebuild_map_from_frames(run, options.frames, options.sequence, options.max_points);
    data["map"] = encode_map(shown, "rebuilt from " + options.frames, 0);
    note = fmt::format(
        "Map: rebuilt from the frames of {} placed by the {} poses of run {} (not deskewed), {} "
        "points (budget {}).",
        html_escape(options.frames), runs.front().optimized ? "loop-closed" : "odometry",
        html_escape(run.label), shown.size(), options.max_points);
  }
  for (const RunFolder& run : runs) {
    if (!fs::is_regular_file(run.path + "/map.pgm") || !fs::is_regular_file(run.path + "/map.yaml"))
      continue;
    data["grid"] = encode_grid(run.path);
    note += fmt::format(" Occupancy grid: map.pgm of run {} ({} x {} cells shown).",
                        html_escape(run.label), data["grid"]["width"].get<int>(),
                        data["grid"]["height"].get<int>());
    break;
  }
  if (data["map"].is_null() && data["grid"].is_null())
    note =
        "No map: no run saved one (odometry --save-map) and no --frames SEQUENCE was given to "
        "rebuild one from the run's poses.";

  html += note +
          " Drag to orbit, right-drag (or shift-drag) to pan, wheel to zoom; hover or click a "
          "frame for its index, step error and health record.</p></div>\n"
          "<pre id=\"view3d-status\">{\"three\":true,\"errors\":[\"the view's script did not "
          "run\"]}</pre>\n"
          // Errors anywhere below, three.js included, end up in the status the tests read.
          "<script>window.view3dErrors=[];window.addEventListener('error',function(e){"
          "window.view3dErrors.push(String(e.message));if(window.view3dPublish)"
          "window.view3dPublish();else document.getElementById('view3d-status').textContent="
          "JSON.stringify({three:true,errors:window.view3dErrors});});</script>\n<script>" +
          script_safe(read_file_bytes(three_path)) + "</script>\n<script>" +
          script_safe(read_file_bytes(controls_path)) +
          "</script>\n<script type=\"application/json\" id=\"view3d-data\">" +
          script_safe(data.dump()) + "</script>\n<script>" + kView3DScript + "</script>\n";
  return html;
}

}  // namespace scanmatch
