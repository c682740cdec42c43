// The report's 3D view (scanmatch/run/report_view3d.hpp): the point budget, the map rebuilt
// from frames, and the page in headless Chromium with WebGL in software (SwiftShader) when
// Chromium is installed: what the scene holds, that it draws, and the page without three.js.
#include <gtest/gtest.h>
#include <zlib.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "scanmatch/geometry/kdtree.hpp"
#include "scanmatch/io/cloud_io.hpp"
#include "scanmatch/io/image.hpp"
#include "scanmatch/run/report.hpp"
#include "scanmatch/run/report_view3d.hpp"
#include "test_helpers.hpp"

using namespace scanmatch;
using scanmatch::testing::error_of;
using scanmatch::testing::read_text;
using scanmatch::testing::run_cli;
using scanmatch::testing::TempDir;

namespace {

using scanmatch::testing::count_occurrences;

const std::string kChromium = "/usr/bin/chromium";

// Debian's libjs-three (scripts/bootstrap), which the report inlines.
bool three_js_installed() {
  return std::filesystem::exists(std::string(kDefaultThreeJsDir) + "/three.min.js");
}

// Chromium as the docs' screenshots run it (scripts/report_screenshot): headless, WebGL in
// SwiftShader, nothing that waits on the network. `what` is "--dump-dom" or "--screenshot=PNG";
// `options` go after the page's #view3d-only (e.g. "&frame=3"). Returns the standard output (the
// DOM for --dump-dom).
std::string run_chromium(const TempDir& dir, const std::string& page, const std::string& what,
                         const std::string& options = "") {
  static int profiles = 0;
  const std::string out = dir.file("chromium_out.txt");
  const std::string command =
      kChromium +
      " --headless --no-sandbox --disable-gpu --disable-quic --no-first-run "
      "--disable-background-networking --disable-component-update --disable-sync "
      "--use-angle=swiftshader --enable-unsafe-swiftshader --hide-scrollbars "
      "--window-size=800,600 --user-data-dir=" +
      dir.file("profile" + std::to_string(profiles++)) + " " + what + " 'file://" + page +
      "#view3d-only" + options + "' > " + out + " 2>/dev/null";
  EXPECT_EQ(std::system(command.c_str()), 0) << command;
  return read_text(out);
}

// The JSON the page wrote into #view3d-status.
nlohmann::json page_status(const std::string& dom) {
  const std::string open = "<pre id=\"view3d-status\">";
  const auto at = dom.find(open);
  if (at == std::string::npos) return {{"missing", true}};
  const auto start = at + open.size();
  return nlohmann::json::parse(dom.substr(start, dom.find("</pre>", start) - start));
}

// Pixels of the screenshot's right half below its top quarter (inside the view's canvas, clear of
// the tool bar above it and the legend at its lower left) that differ from the view's background
// (#15171c) by more than a little, as a share of that region.
double drawn_share(const std::string& png) {
  const Image8 image = read_png(png);
  EXPECT_GE(image.channels, 3);
  std::size_t drawn = 0, pixels = 0;
  for (int y = image.height / 4; y < image.height; ++y)
    for (int x = image.width / 2; x < image.width; ++x, ++pixels) {
      const std::uint8_t* p =
          &image.pixels[(static_cast<std::size_t>(y) * image.width + x) * image.channels];
      drawn += std::abs(p[0] - 0x15) + std::abs(p[1] - 0x17) + std::abs(p[2] - 0x1c) > 40;
    }
  std::printf("%s: %.3f of the view drawn\n", png.c_str(),
              static_cast<double>(drawn) / static_cast<double>(pixels));
  return static_cast<double>(drawn) / static_cast<double>(pixels);
}

// A run of 8 simulated frames with its map, and a loop closure that found the truth with two
// loop edges (as the report's loop-closure test makes one).
std::string loop_closed_run(const TempDir& dir) {
  const std::string run = dir.file("run");
  EXPECT_EQ(run_cli("odometry sim:dynamic-outdoor-fast --frames 8 --quiet --save-map --out " + run)
                .status,
            0);
  std::filesystem::copy_file(run + "/poses_gt_tum.txt", run + "/poses_optimized_tum.txt");
  std::ofstream(run + "/loops.json") << R"([{"from": 0, "to": 7}, {"from": 2, "to": 6}])";
  return run;
}

}  // namespace

// Browsers' screenshots filter their rows (sub, up, average, Paeth): read_png undoes each. A
// 3 x 5 RGB image, one row per filter type, encoded here.
TEST(ReportView3D, PngReaderUndoesEveryRowFilter) {
  const int width = 3, height = 5, channels = 3, row_bytes = width * channels;
  std::vector<std::uint8_t> pixels(row_bytes * height);
  for (std::size_t k = 0; k < pixels.size(); ++k)
    pixels[k] = static_cast<std::uint8_t>(k * 37 + 11);
  const auto at = [&](int row, int k) -> int {
    return row < 0 || k < 0 ? 0 : pixels[static_cast<std::size_t>(row) * row_bytes + k];
  };
  std::string raw;
  for (int row = 0; row < height; ++row) {
    const int filter = row;  // 0 none, 1 sub, 2 up, 3 average, 4 Paeth
    raw.push_back(static_cast<char>(filter));
    for (int k = 0; k < row_bytes; ++k) {
      const int left = at(row, k - channels), up = at(row - 1, k),
                up_left = at(row - 1, k - channels);
      const int p = left + up - up_left;
      const int paeth =
          std::abs(p - left) <= std::abs(p - up) && std::abs(p - left) <= std::abs(p - up_left)
              ? left
          : std::abs(p - up) <= std::abs(p - up_left) ? up
                                                      : up_left;
      const int predictor[] = {0, left, up, (left + up) / 2, paeth};
      raw.push_back(static_cast<char>(at(row, k) - predictor[filter]));
    }
  }
  uLongf size = compressBound(static_cast<uLong>(raw.size()));
  std::string compressed(size, '\0');
  ASSERT_EQ(compress(reinterpret_cast<Bytef*>(compressed.data()), &size,
                     reinterpret_cast<const Bytef*>(raw.data()), static_cast<uLong>(raw.size())),
            Z_OK);
  compressed.resize(size);
  const auto u32 = [](std::uint32_t v) {
    return std::string{static_cast<char>(v >> 24), static_cast<char>(v >> 16),
                       static_cast<char>(v >> 8), static_cast<char>(v)};
  };
  const auto chunk = [&](const std::string& type, const std::string& data) {
    const std::string body = type + data;
    return u32(static_cast<std::uint32_t>(data.size())) + body +
           u32(static_cast<std::uint32_t>(
               crc32(0, reinterpret_cast<const Bytef*>(body.data()), body.size())));
  };
  const std::string header = u32(width) + u32(height) + std::string("\x08\x02\x00\x00\x00", 5);
  TempDir dir;
  scanmatch::testing::write_text(dir.file("filtered.png"),
                                 std::string("\x89PNG\r\n\x1a\n", 8) + chunk("IHDR", header) +
                                     chunk("IDAT", compressed) + chunk("IEND", ""));
  const Image8 image = read_png(dir.file("filtered.png"));
  EXPECT_EQ(image.width, width);
  EXPECT_EQ(image.height, height);
  EXPECT_EQ(image.channels, channels);
  EXPECT_EQ(image.pixels, pixels);
  // Damaged data is refused by name.
  scanmatch::testing::write_text(dir.file("cut.png"), std::string("\x89PNG\r\n\x1a\n", 8) +
                                                          chunk("IHDR", header) +
                                                          chunk("IDAT", compressed.substr(0, 5)));
  EXPECT_NE(error_of([&] { read_png(dir.file("cut.png")); }).find("cut.png"), std::string::npos);
}

TEST(ReportView3D, Base64IsRfc4648) {
  EXPECT_EQ(base64_encode(""), "");
  EXPECT_EQ(base64_encode("f"), "Zg==");
  EXPECT_EQ(base64_encode("fo"), "Zm8=");
  EXPECT_EQ(base64_encode("foo"), "Zm9v");
  EXPECT_EQ(base64_encode("foobar"), "Zm9vYmFy");
  EXPECT_EQ(base64_encode(std::string("\xff\x00\x80", 3)), "/wCA");
}

TEST(ReportView3D, BudgetKeepsPointsSpreadAndTheirIntensities) {
  // A 200 x 200 floor at 5 cm, intensity = x: the kept points keep their own intensity.
  PointCloud floor;
  for (int i = 0; i < 200; ++i)
    for (int j = 0; j < 200; ++j) {
      floor.points.emplace_back(0.05f * i, 0.05f * j, 0.0f);
      floor.intensity.push_back(0.05f * i);
    }
  EXPECT_EQ(downsample_to_budget(floor, 40000).size(), 40000u);  // within budget: as is
  PointCloud with_nan = floor;
  with_nan.points[7].y() = std::nanf("");
  EXPECT_EQ(downsample_to_budget(with_nan, 40000).size(), 39999u);  // but finite
  const PointCloud kept = downsample_to_budget(floor, 1000);
  ASSERT_EQ(kept.size(), 1000u);
  ASSERT_EQ(kept.intensity.size(), 1000u);
  Eigen::AlignedBox3f box;
  for (std::size_t k = 0; k < kept.size(); ++k) {
    EXPECT_FLOAT_EQ(kept.intensity[k], kept.points[k].x());
    box.extend(kept.points[k]);
  }
  // Spread over the whole floor, not its first rows.
  EXPECT_GT(box.sizes().x(), 9.0f);
  EXPECT_GT(box.sizes().y(), 9.0f);
  EXPECT_THROW(downsample_to_budget(floor, 0), Error);
}

TEST(ReportView3D, MapRebuiltFromFramesLiesOnTheSavedMap) {
  TempDir dir;
  const std::string run = dir.file("run");
  ASSERT_EQ(run_cli("odometry sim:dynamic-outdoor-fast --frames 6 --quiet --save-map --out " + run)
                .status,
            0);
  const RunFolder folder = read_run_folder(run);
  const PointCloud rebuilt = rebuild_map_from_frames(folder, "sim:dynamic-outdoor-fast", {}, 20000);
  EXPECT_EQ(rebuilt.size(), 20000u);  // the frames hold many more
  // The same frames placed by the same poses: on the saved map (its voxels are 0.5 m at most),
  // save for the few points the deskewing moved.
  const PointCloud saved = read_cloud(run + "/map.pcd");
  const KdTree tree(saved.points);
  std::size_t near = 0, index = 0;
  float squared = 0;
  for (const Point& p : rebuilt.points) near += tree.nearest(p, 0.5f * 0.5f, index, squared);
  EXPECT_GT(static_cast<double>(near) / rebuilt.size(), 0.95);

  // Another sequence is refused: fewer frames than the run has poses.
  const std::string other = dir.file("other");
  ASSERT_EQ(run_cli("simulate dynamic-outdoor-fast --frames 3 --quiet --out " + other).status, 0);
  const std::string error = error_of([&] { rebuild_map_from_frames(folder, other, {}, 1000); });
  EXPECT_NE(error.find("not the sequence it read"), std::string::npos) << error;
}

TEST(ReportView3D, DamagedGridIsRefusedByName) {
  // A map2d-like run folder with a grid, and a stand-in three.js (only inlined, never run here).
  TempDir dir;
  const std::string run = dir.file("run"), three = dir.file("three");
  std::filesystem::create_directories(run);
  std::filesystem::create_directories(three + "/examples/js/controls");
  scanmatch::testing::write_text(three + "/three.min.js", "");
  scanmatch::testing::write_text(three + "/examples/js/controls/OrbitControls.js", "");
  scanmatch::testing::write_text(run + "/poses_tum.txt", "0 0 0 0 0 0 0 1\n1 1 0 0 0 0 0 1\n");
  const std::string yaml = "image: map.pgm\nresolution: 0.5\norigin: [-1.0, -2.0, 0.0]\n";
  scanmatch::testing::write_text(run + "/map.yaml", yaml);
  scanmatch::testing::write_text(run + "/map.pgm",
                                 std::string("P5\n4 3\n255\n") + std::string(12, '\xfe'));
  View3DOptions options;
  options.three_js_dir = three;
  const std::string html = render_view3d({read_run_folder(run)}, std::nullopt, options);
  EXPECT_NE(html.find("\"width\":4"), std::string::npos);
  EXPECT_NE(html.find("\"origin\":[-1.0,-2.0]"), std::string::npos);

  scanmatch::testing::write_text(run + "/map.pgm",
                                 std::string("P5\n4 3\n255\n") + std::string(5, '\xfe'));
  std::string error =
      error_of([&] { render_view3d({read_run_folder(run)}, std::nullopt, options); });
  EXPECT_NE(error.find("map.pgm"), std::string::npos) << error;
  scanmatch::testing::write_text(run + "/map.pgm", std::string("P2\n4 3\n255\n"));
  error = error_of([&] { render_view3d({read_run_folder(run)}, std::nullopt, options); });
  EXPECT_NE(error.find("not an 8-bit binary PGM"), std::string::npos) << error;
  scanmatch::testing::write_text(run + "/map.pgm",
                                 std::string("P5\n4 3\n255\n") + std::string(12, '\xfe'));
  scanmatch::testing::write_text(run + "/map.yaml", "image: map.pgm\norigin: [0, 0, 0]\n");
  error = error_of([&] { render_view3d({read_run_folder(run)}, std::nullopt, options); });
  EXPECT_NE(error.find("map.yaml"), std::string::npos) << error;
}

TEST(ReportView3D, PageDrawsMapTrajectoriesAndLoopsInChromium) {
  if (!three_js_installed()) GTEST_SKIP() << "libjs-three not installed (scripts/bootstrap)";
  TempDir dir;
  const std::string run = loop_closed_run(dir);
  const std::string page = dir.file("report.html");
  const auto r = run_cli("report " + run + " --out " + page);
  ASSERT_EQ(r.status, 0) << r.output;
  const std::string html = read_text(page);
  // One file: three.js inline, nothing fetched.
  EXPECT_GT(count_occurrences(html, "<script>"), 2u);
  EXPECT_EQ(count_occurrences(html, "<script src"), 0u);
  EXPECT_NE(html.find("id=\"view3d-data\""), std::string::npos);
  if (!std::filesystem::exists(kChromium))
    GTEST_SKIP() << "chromium not installed (scripts/bootstrap --browser): 3D view not checked";

  // Opened as a click on frame 3 would leave it.
  const std::string dom = run_chromium(dir, page, "--dump-dom", "&frame=3");
  const nlohmann::json status = page_status(dom);
  EXPECT_EQ(status.value("errors", nlohmann::json::array({"no status"})), nlohmann::json::array())
      << status.dump();
  ASSERT_TRUE(status.value("webgl", false)) << status.dump();
  const auto tip = dom.find("<div id=\"view3d-tip\"");
  ASSERT_NE(tip, std::string::npos);
  const std::string tip_text = dom.substr(tip, dom.find("</div>", tip) - tip);
  EXPECT_NE(tip_text.find("run (ctf-icp), frame 3\nstep error: "), std::string::npos) << tip_text;
  EXPECT_NE(tip_text.find(" m, "), std::string::npos) << tip_text;  // against the reference
  EXPECT_NE(tip_text.find("health: "), std::string::npos) << tip_text;
  // Every point of the saved map (within the budget), the odometry, the loop-closed poses and
  // the reference (8 poses each), both loop edges.
  const PointCloud saved = read_cloud(run + "/map.pcd");
  EXPECT_EQ(status["points"].get<std::size_t>(), saved.size());
  EXPECT_EQ(status["trajectory_vertices"].get<int>(), 3 * 8);
  EXPECT_EQ(status["loop_edges"].get<int>(), 2);
  // The frames the record flagged are those summary.json counts as not to be trusted or noted.
  const RunFolder folder = read_run_folder(run);
  std::size_t flagged = 0;
  for (const FrameRecord& f : folder.timing) flagged += !frame_health_flags(f.stats).empty();
  EXPECT_EQ(status["flagged_frames"].get<std::size_t>() + status["noted_frames"].get<std::size_t>(),
            flagged);

  // The screenshot shows the map: a good share of the view is not background.
  const std::string png = dir.file("view.png");
  run_chromium(dir, page, "--screenshot=" + png);
  const double drawn = drawn_share(png);
  EXPECT_GT(drawn, 0.05) << png;

  // Without a saved map: rebuilt from the frames, to the budget.
  std::filesystem::remove(run + "/map.pcd");
  ASSERT_EQ(run_cli("report " + run +
                    " --frames sim:dynamic-outdoor-fast --max-points 5000 --out " + page)
                .status,
            0);
  const nlohmann::json rebuilt = page_status(run_chromium(dir, page, "--dump-dom"));
  EXPECT_EQ(rebuilt.value("errors", nlohmann::json::array({"no status"})), nlohmann::json::array());
  EXPECT_EQ(rebuilt["points"].get<int>(), 5000) << rebuilt.dump();
  EXPECT_EQ(rebuilt["color"], "height");

  // A map with intensities can be coloured by them (these frames have none).
  PointCloud bright = saved;
  for (const Point& p : bright.points) bright.intensity.push_back(p.z());
  write_cloud(run + "/map.pcd", bright);
  ASSERT_EQ(run_cli("report " + run + " --out " + page).status, 0);
  const nlohmann::json by_intensity =
      page_status(run_chromium(dir, page, "--dump-dom", "&color=intensity"));
  EXPECT_EQ(by_intensity.value("errors", nlohmann::json::array({"no status"})),
            nlohmann::json::array());
  EXPECT_EQ(by_intensity["color"], "intensity") << by_intensity.dump();
  EXPECT_EQ(by_intensity["points"].get<std::size_t>(), bright.size());
}

TEST(ReportView3D, WithoutThreeJsThePageKeepsItsTwoDimensionalViews) {
  TempDir dir;
  const std::string run = loop_closed_run(dir);
  const std::string page = dir.file("report.html");
  const auto r =
      run_cli("report " + run + " --three-js " + dir.file("no-three") + " --out " + page);
  ASSERT_EQ(r.status, 0) << r.output;
  const std::string html = read_text(page);
  EXPECT_EQ(count_occurrences(html, "<script"), 0u);  // nothing that could fail
  EXPECT_NE(html.find("needs three.js (the Debian package libjs-three"), std::string::npos);
  const std::size_t svgs = count_occurrences(html, "<svg");
  EXPECT_GE(svgs, 5u);  // top view, step errors, health, timing, map
  if (!std::filesystem::exists(kChromium))
    GTEST_SKIP() << "chromium not installed (scripts/bootstrap --browser): rendering not checked";
  const std::string dom = run_chromium(dir, page, "--dump-dom");
  EXPECT_EQ(page_status(dom), nlohmann::json({{"three", false}}));
  EXPECT_EQ(count_occurrences(dom, "<svg"), svgs);
}

TEST(ReportView3D, Map2DGridAndLoopsInChromium) {
  if (!three_js_installed()) GTEST_SKIP() << "libjs-three not installed (scripts/bootstrap)";
  TempDir dir;
  const std::string run = dir.file("room");
  const auto m = run_cli(
      "map2d sim:room-2d --scans 300 --no-motion-distortion --loop-closure "
      "--quiet --out " +
      run);
  ASSERT_EQ(m.status, 0) << m.output;
  const std::string page = dir.file("report.html");
  ASSERT_EQ(run_cli("report " + run + " --out " + page).status, 0);
  if (!std::filesystem::exists(kChromium))
    GTEST_SKIP() << "chromium not installed (scripts/bootstrap --browser): 3D view not checked";
  const nlohmann::json status = page_status(run_chromium(dir, page, "--dump-dom"));
  EXPECT_EQ(status.value("errors", nlohmann::json::array({"no status"})), nlohmann::json::array())
      << status.dump();
  // The grid at its own size (map.pgm's header), the odometry, loop-closed and reference poses,
  // and every loop edge of loops.json.
  std::ifstream pgm(run + "/map.pgm");
  std::string magic;
  int width = 0, height = 0;
  pgm >> magic >> width >> height;
  EXPECT_EQ(status.value("grid", ""), std::to_string(width) + "x" + std::to_string(height));
  const RunFolder folder = read_run_folder(run);
  ASSERT_FALSE(folder.loops.empty());
  EXPECT_EQ(status["trajectory_vertices"].get<std::size_t>(), 3 * folder.poses.size());
  EXPECT_EQ(status["loop_edges"].get<std::size_t>(), folder.loops.size());
  EXPECT_EQ(status["points"].get<int>(), 0);
  const std::string png = dir.file("grid.png");
  run_chromium(dir, page, "--screenshot=" + png);
  EXPECT_GT(drawn_share(png), 0.2) << png;
}
