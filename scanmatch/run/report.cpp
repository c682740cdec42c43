#include "scanmatch/run/report.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "scanmatch/core/error.hpp"
#include "scanmatch/eval/metrics.hpp"
#include "scanmatch/eval/svg_plot.hpp"
#include "scanmatch/io/cloud_io.hpp"
#include "scanmatch/odometry/health.hpp"
#include "scanmatch/run/report_view3d.hpp"

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

// The frames' health records by frame index (timing.csv's `index`).
std::map<std::size_t, const FrameStats*> stats_by_frame(const RunFolder& run) {
  std::map<std::size_t, const FrameStats*> out;
  for (const FrameRecord& r : run.timing) out[r.index] = &r.stats;
  return out;
}

// One run's frames: the error of each step against the reference (when there is one) and the
// health record, over the same frame axis, so that a jump in the error can be read against what
// the pipeline knew at that frame. Plots and a short text naming the worst steps.
std::string per_frame_section(const RunFolder& run, const std::optional<Trajectory>& gt,
                              std::size_t color) {
  const auto stats = stats_by_frame(run);
  const double last_frame = static_cast<double>(std::max<std::size_t>(1, run.poses.size()) - 1);
  const std::pair<double, double> frames{0.0, last_frame};
  std::string html =
      fmt::format("<h3>{} ({})</h3>\n", html_escape(run.label), html_escape(run.method));
  std::string notes;

  // Step error: pose k-1 to pose k of the associated pairs, placed at the estimate's frame k.
  struct Step {
    std::size_t frame;
    double m, deg;
  };
  std::vector<Step> steps;
  if (gt) {
    const Association pairs = associate(*gt, run.poses, /*allow_partial=*/true);
    if (pairs.estimate.size() >= 2) {
      const RelativeErrors e = relative_errors(pairs.ground_truth, pairs.estimate, 1);
      for (std::size_t k = 0; k < e.translation.size(); ++k)
        steps.push_back({pairs.estimate_index[k + 1], e.translation[k], e.rotation[k]});
    }
  }
  html += "<div class=\"plots\">\n";
  if (!steps.empty()) {
    SvgSeries m = make_series("translation", palette_color(color));
    SvgSeries deg = make_series("rotation", palette_color(color));
    m.line_width = deg.line_width = 1.0;
    for (const Step& s : steps) {
      m.points.emplace_back(static_cast<double>(s.frame), s.m);
      deg.points.emplace_back(static_cast<double>(s.frame), s.deg);
    }
    html += svg_plot({m},
                     {"Step error against the reference: translation", "frame",
                      "error of the step to this frame (m)", 620, 260, false},
                     {frames, std::nullopt});
    html += svg_plot({deg},
                     {"Step error against the reference: rotation", "frame",
                      "error of the step to this frame (deg)", 620, 260, false},
                     {frames, std::nullopt});
  } else {
    notes += gt ? "<p>No step-error plot: fewer than two poses pair with the reference.</p>\n"
                : "<p>No step-error plot: this run has no reference (no poses_gt.txt in its "
                  "folder and none given with --gt).</p>\n";
  }

  if (run.timing.empty()) {
    html += "</div>\n";
    return html + notes + "<p>No health plot: the run folder has no timing.csv.</p>\n";
  }
  // Health: the fine stage's paired share (with the thin-map line), and below zero (clear of the
  // legend) marks for frames whose prior was uncertain, that another start recovered, whose stages
  // disagreed or were bridged.
  SvgSeries paired = make_series("fine paired fraction", palette_color(color));
  SvgSeries thin =
      make_series(fmt::format("thin map below {}", health::kThinPairedFraction), "#7f7f7f",
                  {{0.0, health::kThinPairedFraction}, {last_frame, health::kThinPairedFraction}});
  thin.dashed = true;
  thin.line_width = 1.0;
  SvgSeries uncertain = make_series("prior uncertain", "#ff7f0e");
  SvgSeries disagree = make_series(fmt::format("coarse/fine disagree (> {} m or {} deg)",
                                               health::kDisagreementM, health::kDisagreementDeg),
                                   "#d62728");
  SvgSeries bridged = make_series("bridged", "#000000");
  SvgSeries recovered = make_series("recovered by another start", "#2ca02c");
  SvgSeries gap_m = make_series(fmt::format("coarse-fine distance / {} m", health::kDisagreementM),
                                palette_color(color));
  SvgSeries gap_deg = make_series(
      fmt::format("coarse-fine rotation / {} deg", health::kDisagreementDeg), "#9467bd");
  SvgSeries limit = make_series("threshold", "#7f7f7f", {{0.0, 1.0}, {last_frame, 1.0}});
  limit.dashed = true;
  limit.line_width = paired.line_width = gap_m.line_width = gap_deg.line_width = 1.0;
  for (SvgSeries* marks : {&uncertain, &recovered, &disagree, &bridged}) {
    marks->scatter = true;
    marks->dot_radius = 2.5;
  }
  bool pairs_measured = false, stages_measured = false;
  std::size_t n_uncertain = 0, n_recovered = 0, n_thin = 0, n_disagree = 0, n_bridged = 0;
  for (const FrameRecord& r : run.timing) {
    const FrameStats& f = r.stats;
    const double x = static_cast<double>(r.index);
    paired.points.emplace_back(x, f.fine_paired_fraction);
    gap_m.points.emplace_back(x, f.coarse_fine_m / health::kDisagreementM);
    gap_deg.points.emplace_back(x, f.coarse_fine_deg / health::kDisagreementDeg);
    pairs_measured = pairs_measured || f.fine_paired_fraction > 0.0;
    stages_measured = stages_measured || f.coarse_fine_m > 0.0 || f.coarse_fine_deg > 0.0;
    if (f.prior_uncertain) uncertain.points.emplace_back(x, -0.05), ++n_uncertain;
    if (f.recovered) recovered.points.emplace_back(x, -0.09), ++n_recovered;
    if (health::stages_disagree(f)) disagree.points.emplace_back(x, -0.13), ++n_disagree;
    if (f.bridged) bridged.points.emplace_back(x, -0.17), ++n_bridged;
    n_thin += health::thin_map(f);
  }
  std::vector<SvgSeries> health_series;
  if (pairs_measured) health_series = {paired, thin};
  for (SvgSeries* marks : {&uncertain, &recovered, &disagree, &bridged})
    if (!marks->points.empty()) health_series.push_back(*marks);
  html += svg_plot(health_series,
                   {"Health: map pairing and flagged frames", "frame",
                    "share of points paired; marks below 0", 620, 260, false},
                   {frames, std::pair{-0.2, 1.0}});
  if (stages_measured)
    html += svg_plot({gap_m, gap_deg, limit},
                     {"Health: how far the fine stage moved the coarse result", "frame",
                      "multiple of the disagreement threshold", 620, 260, false},
                     {frames, std::nullopt});
  html += "</div>\n" + notes;

  html += fmt::format(
      "<p>{} frames: prior uncertain on {}, recovered by another coarse start on {}, thin map on "
      "{} "
      "(fine paired fraction below {}), coarse and fine stages disagree on {} (more than {} m or "
      "{} "
      "deg), bridged {}.{}</p>\n",
      run.timing.size(), n_uncertain, n_recovered, n_thin, health::kThinPairedFraction, n_disagree,
      health::kDisagreementM, health::kDisagreementDeg, n_bridged,
      pairs_measured ? "" : " This method records no map pairing (frame to frame).");
  if (!steps.empty()) {
    // The worst steps and what the health record said at each: where and why it went wrong.
    std::vector<Step> worst = steps;
    const std::size_t shown = std::min<std::size_t>(5, worst.size());
    std::partial_sort(worst.begin(), worst.begin() + static_cast<std::ptrdiff_t>(shown),
                      worst.end(), [](const Step& a, const Step& b) { return a.m > b.m; });
    html +=
        "<table><tr><th>worst steps: frame</th><th>translation error (m)</th>"
        "<th>rotation error (deg)</th><th>health record</th></tr>\n";
    for (std::size_t k = 0; k < shown; ++k) {
      const auto it = stats.find(worst[k].frame);
      const std::string flags = it == stats.end() ? "-" : frame_health_flags(*it->second);
      html += fmt::format("<tr><td>{}</td><td>{:.3f}</td><td>{:.2f}</td><td>{}</td></tr>\n",
                          worst[k].frame, worst[k].m, worst[k].deg,
                          flags.empty() ? "healthy" : html_escape(flags));
    }
    html += "</table>\n";
  }
  return html;
}

}  // namespace

std::string frame_health_flags(const FrameStats& f) {
  std::vector<std::string> flags;
  if (f.bridged) flags.push_back("bridged");
  if (f.prior_uncertain) flags.push_back("prior uncertain");
  if (f.recovered) flags.push_back("recovered by another start");
  if (health::thin_map(f))
    flags.push_back(fmt::format("thin map ({:.2f} paired)", f.fine_paired_fraction));
  if (health::stages_disagree(f))
    flags.push_back(fmt::format("coarse/fine disagree ({:.2f} m, {:.1f} deg)", f.coarse_fine_m,
                                f.coarse_fine_deg));
  std::string text;
  for (const auto& flag : flags) text += (text.empty() ? "" : ", ") + flag;
  return text;
}

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
    // ATE, RPE and drift of `poses` against the reference as table cells; adds the reference
    // path once and `poses`' error over distance.
    const auto accuracy = [&](const Trajectory& poses, const std::string& label,
                              const std::string& color) -> std::string {
      if (!gt) return "<td>-</td><td>-</td><td>-</td><td>-</td><td>-</td>";
      const Association pairs = associate(*gt, poses, /*allow_partial=*/true);
      const AteResult ate = compute_ate(pairs.ground_truth, pairs.estimate);
      const RpeResult rpe = compute_rpe_frames(pairs.ground_truth, pairs.estimate, 1);
      const KittiDriftResult kitti = compute_kitti_drift(pairs.ground_truth, pairs.estimate);
      if (!any_truth) {
        paths.push_back(make_series("ground truth", "#000000", top_view(pairs.ground_truth)));
        paths.back().line_width = 2.5;
        any_truth = true;
      }
      SvgSeries e = make_series(label, color);
      const std::vector<double> distance = cumulative_distances(pairs.ground_truth);
      for (std::size_t k = 0; k < pairs.estimate.size(); ++k)
        e.points.emplace_back(
            distance[k],
            (pairs.estimate[k].translation() - pairs.ground_truth[k].translation()).norm());
      errors.push_back(std::move(e));
      return fmt::format(
          "<td>{:.3f}</td><td>{}</td><td>{:.3f}</td><td>{:.4f}</td><td>{}</td>", ate.rmse,
          ate.path_length > 0 ? fmt::format("{:.3f}", ate.rmse_percent_of_path) : "still",
          ate.final_drift, rpe.translation_rmse,
          kitti.segments > 0 ? fmt::format("{:.2f}", kitti.translation_percent) : "-");
    };
    const std::string color = palette_color(i);
    html += fmt::format(
        "<tr><td>{}</td><td>{}</td><td>{}</td><td>{:.1f}</td><td>{}</td>{}"
        "<td>{}</td></tr>\n",
        html_escape(run.label), html_escape(run.method), run.poses.size(), run.frames_per_second,
        run.timing.empty() ? std::string("-") : fmt::format("{:.2f}", mean_ms),
        accuracy(run.poses, run.label, color),
        run.timing.empty() ? std::string("-") : std::to_string(bridged));
    paths.push_back(make_series(run.label, color, top_view(run.poses.poses)));
    if (run.optimized) {
      // Loop closure: the odometry fades; the optimized poses and the loop edges between them
      // are drawn over it.
      paths.back().opacity = 0.45;
      paths.back().dashed = true;
      if (gt) {  // likewise its error over distance
        errors.back().opacity = 0.45;
        errors.back().dashed = true;
      }
      const std::string label = run.label + " (loop-closed)";
      html += fmt::format(
          "<tr><td>{}</td><td>{}</td><td>{}</td><td>-</td><td>-</td>{}<td>{} loops</td></tr>\n",
          html_escape(label), html_escape(run.method), run.optimized->size(),
          accuracy(*run.optimized, label, color), run.loops.size());
      const std::vector<Eigen::Vector2d> at = top_view(run.optimized->poses);
      paths.push_back(make_series(label, color, at));
      SvgSeries edges = make_series(fmt::format("loop edges ({})", run.loops.size()), "#2ca02c");
      edges.line_width = 0.8;
      for (const auto& [from, to] : run.loops) {
        if (from >= at.size() || to >= at.size()) continue;
        edges.points.push_back(at[from]);
        edges.points.push_back(at[to]);
        edges.points.emplace_back(std::nan(""), std::nan(""));  // a break between edges
      }
      paths.push_back(std::move(edges));
    }
  }
  html += "</table>\n";
  if (options.view3d.enabled) html += render_view3d(runs, ground_truth, options.view3d);

  html += "<h2>Trajectories</h2>\n<div class=\"plots\">\n";
  html += svg_plot(paths, {"Top view", "x (m)", "y (m)", 620, 520, true});
  if (!errors.empty())
    html += svg_plot(errors, {"Position error over distance", "distance travelled (m)",
                              "position error (m)", 620, 520, false});
  html += "</div>\n";

  html +=
      "<h2>Per frame: step error and health</h2>\n<p>Each step's error is that of the relative "
      "motion from the previous frame to this one against the reference; the health record is "
      "timing.csv's (summary.json counts with the same thresholds).</p>\n";
  for (std::size_t i = 0; i < runs.size(); ++i)
    html += per_frame_section(runs[i], ground_truth ? ground_truth : runs[i].ground_truth, i);

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
