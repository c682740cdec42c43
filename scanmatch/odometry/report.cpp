#include "scanmatch/odometry/report.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "scanmatch/core/error.hpp"
#include "scanmatch/eval/metrics.hpp"
#include "scanmatch/eval/svg_plot.hpp"
#include "scanmatch/io/cloud_io.hpp"

namespace scanmatch {
namespace {

const char* kStyle =
    "body{font-family:sans-serif;margin:24px;color:#222;max-width:1400px}"
    "table{border-collapse:collapse;margin:8px 0 20px}"
    "td,th{border:1px solid #ccc;padding:4px 10px;text-align:right}"
    "th{background:#f2f2f2}td:first-child,th:first-child{text-align:left}"
    ".plots{display:flex;flex-wrap:wrap;gap:12px}h2{margin-top:28px}";

std::vector<Eigen::Vector2d> top_view(const std::vector<Pose>& poses) {
  std::vector<Eigen::Vector2d> xy;
  for (const Pose& p : poses) xy.emplace_back(p.translation().x(), p.translation().y());
  return xy;
}

}  // namespace

std::string render_report(const std::vector<RunFolder>& runs,
                          const std::optional<Trajectory>& ground_truth,
                          const ReportOptions& options) {
  if (runs.empty()) throw Error("report: no run folders given");
  std::string html = fmt::format(
      "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>{0}</title><style>{1}"
      "</style></head><body>\n<h1>{0}</h1>\n{2}",
      html_escape(options.title), kStyle, options.preamble_html);

  // Accuracy and speed table.
  html +=
      "<h2>Runs</h2>\n<table><tr><th>run</th><th>method</th><th>frames</th><th>frames/s</th>"
      "<th>mean ms</th><th>ATE RMSE (m)</th><th>ATE % of path</th><th>final drift (m)</th>"
      "<th>RPE 1 frame (m)</th><th>KITTI drift %</th><th>bridged</th></tr>\n";
  std::vector<SvgSeries> paths, errors;
  bool any_truth = false;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const RunFolder& run = runs[i];
    const std::optional<Trajectory>& gt = ground_truth ? ground_truth : run.ground_truth;
    double mean_ms = 0;
    std::size_t bridged = 0;
    for (const auto& t : run.timing)
      mean_ms += t.stats.total_ms / static_cast<double>(run.timing.size());
    for (const auto& t : run.timing) bridged += t.stats.bridged;
    std::string accuracy = "<td>-</td><td>-</td><td>-</td><td>-</td><td>-</td>";
    if (gt) {
      const Association pairs = associate(*gt, run.poses, /*allow_partial=*/true);
      const AteResult ate = compute_ate(pairs.ground_truth, pairs.estimate);
      const RpeResult rpe = compute_rpe_frames(pairs.ground_truth, pairs.estimate, 1);
      const KittiDriftResult kitti = compute_kitti_drift(pairs.ground_truth, pairs.estimate);
      accuracy = fmt::format(
          "<td>{:.3f}</td><td>{}</td><td>{:.3f}</td><td>{:.4f}</td><td>{}</td>", ate.rmse,
          ate.path_length > 0 ? fmt::format("{:.3f}", ate.rmse_percent_of_path) : "still",
          ate.final_drift, rpe.translation_rmse,
          kitti.segments > 0 ? fmt::format("{:.2f}", kitti.translation_percent) : "-");
      if (!any_truth) {
        paths.push_back(make_series("ground truth", "#000000", top_view(pairs.ground_truth)));
        paths.back().line_width = 2.5;
        any_truth = true;
      }
      SvgSeries e = make_series(run.label, palette_color(i));
      const std::vector<double> distance = cumulative_distances(pairs.ground_truth);
      for (std::size_t k = 0; k < pairs.estimate.size(); ++k)
        e.points.emplace_back(
            distance[k],
            (pairs.estimate[k].translation() - pairs.ground_truth[k].translation()).norm());
      errors.push_back(std::move(e));
    }
    paths.push_back(make_series(run.label, palette_color(i), top_view(run.poses.poses)));
    html += fmt::format(
        "<tr><td>{}</td><td>{}</td><td>{}</td><td>{:.1f}</td><td>{:.2f}</td>{}"
        "<td>{}</td></tr>\n",
        html_escape(run.label), html_escape(run.method), run.poses.size(), run.frames_per_second,
        mean_ms, accuracy, bridged);
  }
  html += "</table>\n";

  html += "<h2>Trajectories</h2>\n<div class=\"plots\">\n";
  html += svg_plot(paths, {"Top view", "x (m)", "y (m)", 620, 520, true});
  if (!errors.empty())
    html += svg_plot(errors, {"Position error over distance", "distance travelled (m)",
                              "position error (m)", 620, 520, false});
  html += "</div>\n";

  html += "<h2>Time per frame</h2>\n<div class=\"plots\">\n";
  for (const RunFolder& run : runs) {
    if (run.timing.empty()) continue;
    std::vector<SvgSeries> stages = {
        make_series("preprocess", palette_color(2)), make_series("coarse", palette_color(3)),
        make_series("fine", palette_color(0)), make_series("map update", palette_color(4)),
        make_series("total", "#000000")};
    for (std::size_t k = 0; k < run.timing.size(); ++k) {
      const FrameStats& t = run.timing[k].stats;
      const double x = static_cast<double>(k);
      stages[0].points.emplace_back(x, t.preprocess_ms);
      stages[1].points.emplace_back(x, t.coarse_ms);
      stages[2].points.emplace_back(x, t.fine_ms);
      stages[3].points.emplace_back(x, t.map_ms);
      stages[4].points.emplace_back(x, t.total_ms);
    }
    for (auto& s : stages) s.line_width = 1.0;
    html += svg_plot(stages, {run.label + " (" + run.method + ")", "frame", "ms", 620, 300, false});
  }
  html += "</div>\n";

  for (std::size_t i = 0; i < runs.size(); ++i) {
    if (!runs[i].has_map) continue;
    const PointCloud map = read_cloud(runs[i].path + "/map.pcd");
    const std::size_t step = std::max<std::size_t>(1, map.size() / options.max_map_points);
    SvgSeries side = make_series("", "#333333"), top = make_series("", "#333333");
    side.scatter = top.scatter = true;
    side.dot_radius = top.dot_radius = 0.6;
    side.opacity = top.opacity = 0.5;
    for (std::size_t k = 0; k < map.size(); k += step) {
      const Point& p = map.points[k];
      side.points.emplace_back(p.x(), p.z());
      top.points.emplace_back(p.x(), p.y());
    }
    SvgSeries path = make_series("trajectory", palette_color(i), top_view(runs[i].poses.poses));
    html += fmt::format("<h2>Map of {} ({} points, {} shown)</h2>\n<div class=\"plots\">\n",
                        html_escape(runs[i].label), map.size(), side.points.size());
    html += svg_plot({top, path}, {"Top view", "x (m)", "y (m)", 620, 520, true});
    html += svg_plot({side}, {"Side view", "x (m)", "z (m)", 620, 300, true});
    html += "</div>\n";
    break;  // one map is enough to look at
  }
  return html + "</body></html>\n";
}

}  // namespace scanmatch
