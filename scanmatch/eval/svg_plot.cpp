#include "scanmatch/eval/svg_plot.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <tuple>

namespace scanmatch {
namespace {

// A step of 1, 2 or 5 times a power of ten giving about `count` intervals over `span`.
double nice_step(double span, int count) {
  const double raw = span / count;
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  const double f = raw / power;
  return (f < 1.5 ? 1.0 : f < 3.5 ? 2.0 : f < 7.5 ? 5.0 : 10.0) * power;
}

std::string number(double v, double step) {
  const int decimals = std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)));
  return fmt::format("{:.{}f}", std::abs(v) < 1e-12 ? 0.0 : v, decimals);
}

// Clip-path ids must be unique within a page that holds several plots.
std::atomic<int> next_clip_id{0};

}  // namespace

std::string palette_color(std::size_t i) {
  static const char* colors[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd",
                                 "#8c564b", "#e377c2", "#17becf", "#7f7f7f", "#bcbd22"};
  return colors[i % (sizeof colors / sizeof colors[0])];
}

std::string html_escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string svg_plot(const std::vector<SvgSeries>& series, const SvgPlotOptions& o,
                     const SvgAxisRanges& ranges) {
  const double left = 64, right = 16, top = o.title.empty() ? 14 : 34, bottom = 46;
  const double plot_w = o.width - left - right, plot_h = o.height - top - bottom;
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  for (const auto& s : series)
    for (const auto& p : s.points) {
      if (!p.allFinite()) continue;
      x0 = std::min(x0, p.x());
      x1 = std::max(x1, p.x());
      y0 = std::min(y0, p.y());
      y1 = std::max(y1, p.y());
    }
  if (!std::isfinite(x0)) x0 = y0 = 0, x1 = y1 = 1;
  if (ranges.x) std::tie(x0, x1) = *ranges.x;
  if (ranges.y) std::tie(y0, y1) = *ranges.y;
  if (x1 - x0 < 1e-9) x0 -= 0.5, x1 += 0.5;
  if (y1 - y0 < 1e-9) y0 -= 0.5, y1 += 0.5;
  // 4 % margins, then equal aspect by widening the narrower range.
  const double mx = 0.04 * (x1 - x0), my = 0.04 * (y1 - y0);
  x0 -= mx, x1 += mx, y0 -= my, y1 += my;
  if (o.equal_aspect) {
    const double sx = (x1 - x0) / plot_w, sy = (y1 - y0) / plot_h;
    if (sx > sy) {
      const double c = 0.5 * (y0 + y1), h = 0.5 * sx * plot_h;
      y0 = c - h, y1 = c + h;
    } else {
      const double c = 0.5 * (x0 + x1), w = 0.5 * sy * plot_w;
      x0 = c - w, x1 = c + w;
    }
  }
  const auto X = [&](double x) { return left + (x - x0) / (x1 - x0) * plot_w; };
  const auto Y = [&](double y) { return top + (1.0 - (y - y0) / (y1 - y0)) * plot_h; };

  std::string svg = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{}\" height=\"{}\" viewBox=\"0 0 {} {}\" "
      "font-family=\"sans-serif\" font-size=\"11\">\n<rect width=\"100%\" height=\"100%\" "
      "fill=\"white\"/>\n",
      o.width, o.height, o.width, o.height);
  if (!o.title.empty())
    svg += fmt::format(
        "<text x=\"{}\" y=\"20\" text-anchor=\"middle\" font-size=\"13\" "
        "font-weight=\"bold\">{}</text>\n",
        left + plot_w / 2, html_escape(o.title));
  // Grid and ticks.
  const double xs = nice_step(x1 - x0, 6), ys = nice_step(y1 - y0, 5);
  for (double x = std::ceil(x0 / xs) * xs; x <= x1 + 1e-9 * xs; x += xs)
    svg += fmt::format(
        "<line x1=\"{0:.1f}\" y1=\"{1:.1f}\" x2=\"{0:.1f}\" y2=\"{2:.1f}\" stroke=\"#e5e5e5\"/>"
        "<text x=\"{0:.1f}\" y=\"{3:.1f}\" text-anchor=\"middle\">{4}</text>\n",
        X(x), top, top + plot_h, top + plot_h + 14, number(x, xs));
  for (double y = std::ceil(y0 / ys) * ys; y <= y1 + 1e-9 * ys; y += ys)
    svg += fmt::format(
        "<line x1=\"{0:.1f}\" y1=\"{1:.1f}\" x2=\"{2:.1f}\" y2=\"{1:.1f}\" stroke=\"#e5e5e5\"/>"
        "<text x=\"{3:.1f}\" y=\"{4:.1f}\" text-anchor=\"end\">{5}</text>\n",
        left, Y(y), left + plot_w, left - 5, Y(y) + 4, number(y, ys));
  svg += fmt::format(
      "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" "
      "stroke=\"#333\"/>\n",
      left, top, plot_w, plot_h);
  svg += fmt::format("<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">{}</text>\n",
                     left + plot_w / 2, o.height - 8, html_escape(o.x_label));
  svg += fmt::format(
      "<text transform=\"translate(14,{}) rotate(-90)\" text-anchor=\"middle\">{}"
      "</text>\n",
      top + plot_h / 2, html_escape(o.y_label));
  // Data, clipped to the frame.
  svg += fmt::format(
      "<clipPath id=\"c{0}\"><rect x=\"{1}\" y=\"{2}\" width=\"{3}\" "
      "height=\"{4}\"/></clipPath><g clip-path=\"url(#c{0})\">\n",
      reinterpret_cast<std::uintptr_t>(&series) % 1000000, left, top, plot_w, plot_h);
  for (const auto& s : series) {
    if (s.scatter) {
      svg += fmt::format("<g fill=\"{}\" fill-opacity=\"{}\">", s.color, s.opacity);
      for (const auto& p : s.points)
        if (p.allFinite())
          svg += fmt::format("<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"{}\"/>", X(p.x()), Y(p.y()),
                             s.dot_radius);
      svg += "</g>\n";
      continue;
    }
    std::string path;
    bool pen_down = false;
    for (const auto& p : s.points) {
      if (!p.allFinite()) {
        pen_down = false;
        continue;
      }
      path += fmt::format("{}{:.1f},{:.1f}", pen_down ? " L" : " M", X(p.x()), Y(p.y()));
      pen_down = true;
    }
    if (!path.empty())
      svg += fmt::format(
          "<path d=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"{}\" "
          "stroke-opacity=\"{}\" stroke-linejoin=\"round\"{}/>\n",
          path, s.color, s.line_width, s.opacity, s.dashed ? " stroke-dasharray=\"6,4\"" : "");
  }
  svg += "</g>\n";
  // Legend, top left inside the frame.
  double ly = top + 8;
  for (const auto& s : series) {
    if (s.label.empty()) continue;
    svg += fmt::format(
        "<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"14\" height=\"4\" fill=\"{}\"/>"
        "<text x=\"{:.1f}\" y=\"{:.1f}\">{}</text>\n",
        left + 8, ly + 2, s.color, left + 26, ly + 7, html_escape(s.label));
    ly += 15;
  }
  return svg + "</svg>\n";
}

}  // namespace scanmatch
