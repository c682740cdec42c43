// The HTML report, the result tables and `scanmatch bench` end to end; the report's rendering
// in headless Chromium when it is installed.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

#include "scanmatch/core/error.hpp"
#include "scanmatch/eval/svg_plot.hpp"
#include "scanmatch/eval/table.hpp"
#include "scanmatch/odometry/frame_odometry.hpp"
#include "scanmatch/run/report.hpp"
#include "test_helpers.hpp"

using namespace scanmatch;
using scanmatch::testing::count_occurrences;
using scanmatch::testing::read_text;
using scanmatch::testing::run_cli;
using scanmatch::testing::shared_data;
using scanmatch::testing::TempDir;

TEST(Report, SvgPlotMapsDataIntoTheFrame) {
  SvgSeries line = make_series("a<b", "#123456", {{0, 0}, {10, 5}});
  const std::string svg = svg_plot({line}, {"T", "x", "y", 400, 300, true});
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  EXPECT_NE(svg.find("a&lt;b"), std::string::npos);  // escaped legend
  EXPECT_NE(svg.find("stroke=\"#123456\""), std::string::npos);
  EXPECT_EQ(count_occurrences(svg, "<path"), 1u);
  // Empty input still gives a valid, empty frame.
  EXPECT_NE(svg_plot({}, {}).find("</svg>"), std::string::npos);
}

TEST(Report, TablesRenderAsMarkdownCsvAndHtml) {
  const ResultTable t{"ATE, %", "note", {"sequence", "a", "b"}, {{"s1", "0.1", "1,5"}}};
  EXPECT_NE(to_markdown(t).find("| s1 | 0.1 | 1,5 |"), std::string::npos);
  EXPECT_NE(to_csv(t).find("\"ATE, %\",s1,0.1,\"1,5\""), std::string::npos);
  EXPECT_NE(to_html(t).find("<td>1,5</td>"), std::string::npos);
}

TEST(Report, OdometryRunsBecomeOneSelfContainedPage) {
  TempDir dir;
  for (const std::string method : {"ctf-icp", "ndt"})
    ASSERT_EQ(run_cli("odometry sim:dynamic-outdoor-fast --frames 8 --quiet --save-map --method " +
                      method + " --out " + dir.file(method))
                  .status,
              0);
  const auto r = run_cli("report " + dir.file("ctf-icp") + " " + dir.file("ndt") + " --out " +
                         dir.file("report.html"));
  ASSERT_EQ(r.status, 0) << r.output;
  const std::string html = read_text(dir.file("report.html"));
  // Top view, error over distance, stage times of both runs, the map from above and the side;
  // per run the step error (translation, rotation) and the health record (ctf-icp adds its
  // coarse/fine disagreement; ndt has no such stages).
  EXPECT_EQ(count_occurrences(html, "<svg"), 6u + 4u + 3u);
  EXPECT_NE(html.find("ground truth"), std::string::npos);
  EXPECT_EQ(html.find("http://www.w3.org/2000/svg") != std::string::npos, true);
  // Nothing to fetch: the 3D view's scripts (report_view3d.hpp) are inline.
  EXPECT_EQ(count_occurrences(html, "<script src"), 0u);
  EXPECT_EQ(count_occurrences(html, "src=\"http"), 0u);
  // A folder that is not a run is refused by name.
  const auto bad = run_cli("report " + dir.path().string() + " --out " + dir.file("x.html"));
  EXPECT_NE(bad.status, 0);
  EXPECT_NE(bad.output.find("not a run folder"), std::string::npos) << bad.output;

  const std::string chromium = "/usr/bin/chromium";
  if (!std::filesystem::exists(chromium))
    GTEST_SKIP() << "chromium not installed (scripts/bootstrap --browser): rendering not checked";
  const std::string dom = dir.file("dom.html");
  const std::string command =
      chromium +
      " --headless --no-sandbox --disable-gpu --disable-quic --no-first-run "
      "--disable-background-networking --disable-component-update --disable-sync "
      "--user-data-dir=" +
      dir.file("profile") + " --dump-dom file://" + dir.file("report.html") + " > " + dom +
      " 2>/dev/null";
  ASSERT_EQ(std::system(command.c_str()), 0);
  const std::string rendered = read_text(dom);
  EXPECT_EQ(count_occurrences(rendered, "<svg"), 6u + 4u + 3u);
  EXPECT_NE(rendered.find("Position error over distance"), std::string::npos);
}

TEST(Report, EachRunShowsItsStepErrorAndHealthOverFrames) {
  TempDir dir;
  const std::string with = dir.file("with_ref"), without = dir.file("no_ref");
  ASSERT_EQ(
      run_cli("odometry sim:dynamic-outdoor-fast --frames 8 --quiet --method ctf-icp --out " + with)
          .status,
      0);
  // Every run folder counts its health flags, the recoveries among them.
  const auto summary = nlohmann::json::parse(scanmatch::testing::read_text(with + "/summary.json"));
  for (const char* key :
       {"uncertain_priors", "recoveries", "global_starts", "thin_map_frames",
        "coarse_fine_disagreements", "median_fine_paired_fraction", "elevation_correction_deg"})
    EXPECT_TRUE(summary.at("health").contains(key)) << key;
  // The same run without its ground truth: nothing to measure the steps against.
  std::filesystem::copy(with, without);
  std::filesystem::remove(without + "/poses_gt.txt");
  std::filesystem::remove(without + "/poses_gt_tum.txt");
  const std::string html =
      render_report({read_run_folder(with), read_run_folder(without)}, std::nullopt);
  const auto at_with = html.find("<h3>with_ref (ctf-icp)"),
             at_without = html.find("<h3>no_ref (ctf-icp)");
  ASSERT_NE(at_with, std::string::npos);
  ASSERT_NE(at_without, std::string::npos);
  ASSERT_LT(at_with, at_without);
  const std::string with_part = html.substr(at_with, at_without - at_with);
  const std::string without_part =
      html.substr(at_without, html.find("<h2>", at_without) - at_without);

  // With a reference: translation and rotation error of every step, the health record, and the
  // worst steps named with what the record said there.
  EXPECT_EQ(count_occurrences(with_part, "Step error against the reference: translation"), 1u);
  EXPECT_EQ(count_occurrences(with_part, "Step error against the reference: rotation"), 1u);
  EXPECT_EQ(count_occurrences(with_part, "Health: map pairing and flagged frames"), 1u);
  EXPECT_NE(with_part.find("worst steps"), std::string::npos);
  EXPECT_EQ(with_part.find("No step-error plot"), std::string::npos);
  // The thresholds summary.json counts with, drawn and stated.
  EXPECT_NE(with_part.find("thin map below 0.3"), std::string::npos);
  EXPECT_NE(with_part.find("recovered by another coarse start on"), std::string::npos);
  EXPECT_NE(with_part.find("more than 0.25 m or 3 deg"), std::string::npos);
  EXPECT_NE(with_part.find("stroke-dasharray"), std::string::npos);

  // Without: the health plot only, and why there is no error plot.
  EXPECT_EQ(without_part.find("Step error against the reference"), std::string::npos);
  EXPECT_EQ(count_occurrences(without_part, "Health: map pairing and flagged frames"), 1u);
  EXPECT_NE(without_part.find("No step-error plot: this run has no reference"), std::string::npos);
  EXPECT_EQ(count_occurrences(html, "<script src"), 0u);
}

TEST(Bench, OneRunGivesEveryTableForEveryMethod) {
  TempDir dir;
  const auto r = run_cli(
      "bench --preset static-indoor --preset dynamic-outdoor-fast --frames 6 "
      "--method ctf-icp --method ndt --quiet --out " +
      dir.file("b"));
  ASSERT_EQ(r.status, 0) << r.output;
  const std::string md = read_text(dir.file("b/tables.md"));
  for (const std::string title : {"CTF-ICP Table 2", "CTF-ICP Table 3", "CTF-ICP Table 4",
                                  "CTF-ICP Table 5", "Still sensor", "LOAM paper"})
    EXPECT_NE(md.find(title), std::string::npos) << title;
  EXPECT_NE(md.find("| dynamic-outdoor-fast |"), std::string::npos);
  EXPECT_NE(read_text(dir.file("b/tables.csv")).find("static-indoor"), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(dir.file("b/report.html")));
  EXPECT_TRUE(
      std::filesystem::exists(dir.file("b/runs/dynamic-outdoor-fast/ctf-icp_no-fine/poses.txt")));
  const auto bad = run_cli("bench --method magic --out " + dir.file("c"));
  EXPECT_NE(bad.status, 0);
  EXPECT_NE(bad.output.find("magic"), std::string::npos);
}

TEST(Bench, RecordedFolderUsesTheReferenceBesideItsFrames) {
  TempDir dir;
  // A folder like avia_hku1: frames/, times.txt and a SLAM reference named odom_poses.txt.
  const std::string rec = dir.file("rec");
  ASSERT_EQ(run_cli("simulate dynamic-outdoor-fast --frames 6 --quiet --out " + rec).status, 0);
  std::filesystem::rename(rec + "/poses_gt.txt", rec + "/odom_poses.txt");
  const auto r =
      run_cli("bench --sequence " + rec +
              " --method ctf-icp,ndt,kiss-icp --no-ablation --quiet --out " + dir.file("b"));
  ASSERT_EQ(r.status, 0) << r.output;
  const std::string md = read_text(dir.file("b/tables.md"));
  EXPECT_NE(md.find("Reference of rec: `" + rec + "/odom_poses.txt`"), std::string::npos) << md;
  // ATE and frames per second, per method, side by side.
  EXPECT_NE(md.find("| method | rec ATE % | rec frames/s |"), std::string::npos) << md;
  EXPECT_NE(md.find("| ctf-icp | "), std::string::npos);
  EXPECT_EQ(md.find("failed"), std::string::npos) << md;
  if (missing_peer_option("kiss-icp").empty()) return;  // a build with KISS-ICP runs it
  // A peer this build lacks is listed as such, not a failure of the bench.
  EXPECT_NE(md.find("| kiss-icp | not built | not built |"), std::string::npos) << md;
  EXPECT_NE(md.find("Not built into this binary: kiss-icp"), std::string::npos);
  const auto list = run_cli("bench --list-methods");
  EXPECT_EQ(list.status, 0) << list.output;
  EXPECT_NE(list.output.find("\nkiss-icp not-built"), std::string::npos) << list.output;
  EXPECT_NE(list.output.find("ctf-icp\n"), std::string::npos);
}

TEST(Bench, RecordedAviaHku1AgainstItsReference) {
  const std::string avia = shared_data("data/3d/avia_hku1");
  if (avia.empty()) GTEST_SKIP() << "../shared/data/3d/avia_hku1 absent: recorded bench not run";
  TempDir dir;
  const auto r = run_cli("bench --sequence " + avia + " --reference " + avia +
                         "/odom_poses.txt --method ctf-icp,ndt --frames 10 --no-ablation "
                         "--quiet --out " +
                         dir.file("b"));
  ASSERT_EQ(r.status, 0) << r.output;
  const std::string md = read_text(dir.file("b/tables.md"));
  EXPECT_NE(md.find("| avia_hku1 | "), std::string::npos) << md;
  EXPECT_NE(md.find("| method | avia_hku1 ATE % | avia_hku1 frames/s |"), std::string::npos);
  EXPECT_EQ(md.find("failed"), std::string::npos) << md;
  EXPECT_TRUE(std::filesystem::exists(dir.file("b/runs/avia_hku1/ctf-icp/poses_gt.txt")));
}

TEST(Report, LoopClosedRunsShowBothTrajectoriesAndTheirLoopEdges) {
  TempDir dir;
  const std::string run = dir.file("run");
  ASSERT_EQ(
      run_cli("odometry sim:dynamic-outdoor-fast --frames 8 --quiet --method ctf-icp --out " + run)
          .status,
      0);
  // A loop closure that found the truth, with two loop edges.
  std::filesystem::copy_file(run + "/poses_gt_tum.txt", run + "/poses_optimized_tum.txt");
  std::ofstream(run + "/loops.json") << R"([{"from": 0, "to": 7}, {"from": 2, "to": 6}])";
  const RunFolder folder = read_run_folder(run);
  ASSERT_TRUE(folder.optimized.has_value());
  EXPECT_EQ(folder.optimized->size(), folder.poses.size());
  ASSERT_EQ(folder.loops.size(), 2u);
  EXPECT_EQ(folder.loops[1], std::make_pair(std::size_t{2}, std::size_t{6}));
  const std::string html = render_report({folder}, std::nullopt);
  // Its own table row with an ATE of zero (it is the reference), the odometry dashed under it,
  // and the loop edges in the legend.
  const auto row = html.find("<td>run (loop-closed)</td>");
  ASSERT_NE(row, std::string::npos);
  const std::string cells = html.substr(row, html.find("</tr>", row) - row);
  EXPECT_NE(cells.find("<td>0.000</td>"), std::string::npos) << cells;
  EXPECT_NE(cells.find("2 loops"), std::string::npos) << cells;
  EXPECT_NE(html.find("loop edges (2)"), std::string::npos);

  // A loop edge past the run's frames is refused, naming the file.
  std::ofstream(run + "/loops.json") << R"([{"from": 0, "to": 99}])";
  try {
    read_run_folder(run);
    FAIL() << "a loop edge past the frames was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("loops.json"), std::string::npos) << e.what();
  }
  std::ofstream(run + "/loops.json") << R"({"from": 0})";
  EXPECT_THROW(read_run_folder(run), Error);
}

TEST(Report, Map2DRunsShowTheirLoopClosureAgainstTheReference) {
  TempDir dir;
  const std::string run = dir.file("room");
  const auto r = run_cli(
      "map2d sim:room-2d --scans 300 --no-motion-distortion --loop-closure "
      "--quiet --out " +
      run);
  ASSERT_EQ(r.status, 0) << r.output;
  // The reference is the log's (here the simulator's) poses; map2d's timing has no 3D stages.
  const RunFolder folder = read_run_folder(run);
  ASSERT_TRUE(folder.ground_truth.has_value());
  EXPECT_EQ(folder.ground_truth->size(), folder.poses.size());
  EXPECT_TRUE(folder.timing.empty());
  EXPECT_GT(folder.frames_per_second, 0.0);
  ASSERT_TRUE(folder.optimized.has_value());
  const std::string html = render_report({folder}, std::nullopt);
  EXPECT_NE(html.find("<td>room (loop-closed)</td>"), std::string::npos);
  EXPECT_NE(html.find("ground truth"), std::string::npos);
}
