#pragma once
// A small SVG plotter of our own for the reports (no network, no scripts): lines and scatter
// series on linear axes with "nice" ticks, a legend and optionally equal aspect (maps, paths).

#include <Eigen/Core>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace scanmatch {

struct SvgSeries {
  std::string label;                    ///< shown in the legend (empty: not listed)
  std::string color = "#1f77b4";        ///< any SVG colour
  std::vector<Eigen::Vector2d> points;  ///< data coordinates; non-finite points break a line
  bool scatter = false;                 ///< dots instead of a polyline
  double line_width = 1.5;              ///< px
  double dot_radius = 1.0;              ///< px, scatter only
  double opacity = 1.0;
  bool dashed = false;  ///< a dashed line (thresholds, references)
};

struct SvgPlotOptions {
  std::string title, x_label, y_label;
  int width = 640, height = 420;  ///< px
  bool equal_aspect = false;      ///< one data unit is as long on both axes
};

/// Fixed axis ranges (min, max) instead of the data's, e.g. for plots over the same frames placed
/// one above the other. A small margin is still added.
struct SvgAxisRanges {
  std::optional<std::pair<double, double>> x, y;
};

/// A line series (a scatter one after setting .scatter).
inline SvgSeries make_series(std::string label, std::string color,
                             std::vector<Eigen::Vector2d> points = {}) {
  SvgSeries s;
  s.label = std::move(label);
  s.color = std::move(color);
  s.points = std::move(points);
  return s;
}

/// The plot as an inline <svg> element. Empty series are skipped; no data gives an empty frame.
std::string svg_plot(const std::vector<SvgSeries>& series, const SvgPlotOptions& options,
                     const SvgAxisRanges& ranges = {});

/// A qualitative palette colour for series i (cycles).
std::string palette_color(std::size_t i);

/// Escapes &, <, >, " for HTML/SVG text.
std::string html_escape(const std::string& text);

}  // namespace scanmatch
