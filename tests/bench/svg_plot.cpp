#include "svg_plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "contract/xml_text.hpp"

namespace balloon::bench {
namespace {

// Panel geometry (px): plot area and the margins for tick labels, axis labels, the title and the legend.
constexpr double PANEL_W = 660, PANEL_H = 360, LEFT = 72, TOP = 34, PLOT_W = 370, PLOT_H = 270, LEGEND_GAP = 14;
constexpr double FIGURE_TOP = 34, FIGURE_BOTTOM = 24;

std::string fixed(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.1f", value);
  return buffer;
}

std::string tick_text(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%g", std::abs(value) < 1e-12 ? 0.0 : value);
  return buffer;
}

/// 1, 2 or 5 times a power of ten: the largest at or below `value` (down) or the smallest at or above it.
double one_two_five(double value, bool down) {
  const double power = std::pow(10.0, std::floor(std::log10(value)));
  if (down) {
    for (const double m : {5.0, 2.0, 1.0})
      if (m * power <= value * (1 + 1e-12)) return m * power;
    return power;
  }
  for (const double m : {1.0, 2.0, 5.0, 10.0})
    if (m * power >= value * (1 - 1e-12)) return m * power;
  return 10.0 * power;
}

/// An axis's range and its mapping to pixels over [pixel_from, pixel_to].
struct Scale {
  bool log = false;
  double lo = 0.0, hi = 1.0;
  double pixel_from = 0.0, pixel_to = 1.0;

  bool drawable(double v) const { return std::isfinite(v) && (!log || v > 0); }
  double operator()(double v) const {
    const double t = log ? (std::log10(v) - std::log10(lo)) / (std::log10(hi) - std::log10(lo)) : (v - lo) / (hi - lo);
    return pixel_from + (pixel_to - pixel_from) * t;
  }
  /// Tick values: 1-2-5 per decade on a log axis (decades only beyond 2.5 of them), about 5 steps on a linear one.
  std::vector<double> ticks() const {
    std::vector<double> out;
    if (log) {
      const bool crowded = std::log10(hi / lo) > 2.5;
      for (int decade = static_cast<int>(std::floor(std::log10(lo))); decade <= static_cast<int>(std::ceil(std::log10(hi)));
           ++decade)
        for (const double m : {1.0, 2.0, 5.0}) {
          const double tick = m * std::pow(10.0, decade);
          if ((crowded && m != 1.0) || tick < lo * (1 - 1e-9) || tick > hi * (1 + 1e-9)) continue;
          out.push_back(tick);
        }
      return out;
    }
    const double step = one_two_five((hi - lo) / 5.0, false);
    for (double tick = std::ceil(lo / step - 1e-9) * step; tick <= hi + 1e-9 * step; tick += step) out.push_back(tick);
    return out;
  }
};

/// The range of one axis over the drawable points: 1-2-5 bounds on a log axis, nice steps from 0 (when
/// every value is >= 0) on a linear one.
Scale fit_scale(const PlotAxis& axis, const std::vector<double>& values, double pixel_from, double pixel_to) {
  Scale scale{axis.log, 0.0, 0.0, pixel_from, pixel_to};
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const double v : values)
    if (scale.drawable(v)) lo = std::min(lo, v), hi = std::max(hi, v);
  if (axis.log) {
    if (!(lo <= hi)) lo = 1.0, hi = 10.0;
    scale.lo = one_two_five(lo, true);
    scale.hi = one_two_five(hi, false);
    if (!(scale.hi > scale.lo)) scale.hi = scale.lo * 10.0;
    return scale;
  }
  if (!(lo <= hi)) lo = 0.0, hi = 1.0;
  if (lo >= 0) lo = 0.0;
  if (!(hi > lo)) hi = lo + 1.0;
  const double step = one_two_five((hi - lo) / 5.0, false);
  scale.lo = std::floor(lo / step) * step;
  scale.hi = std::ceil(hi / step - 1e-9) * step;
  return scale;
}

std::string panel_svg(const PlotPanel& panel, double left, double top) {
  std::vector<double> xs, ys;
  for (const PlotSeries& series : panel.series)
    for (const auto& p : series.points) {
      xs.push_back(p[0]);
      ys.push_back(p[1]);
    }
  const double x0 = left + LEFT, y0 = top + TOP;
  const Scale sx = fit_scale(panel.x, xs, x0, x0 + PLOT_W);
  const Scale sy = fit_scale(panel.y, ys, y0 + PLOT_H, y0);
  std::string svg = "<text x=\"" + fixed(x0) + "\" y=\"" + fixed(top + 20) + "\" font-size=\"13\" font-weight=\"bold\">" +
                    contract::xml_escaped(panel.title) + "</text>\n";
  svg += "<rect x=\"" + fixed(x0) + "\" y=\"" + fixed(y0) + "\" width=\"" + fixed(PLOT_W) + "\" height=\"" + fixed(PLOT_H) +
         "\" fill=\"none\" stroke=\"#888\"/>\n";
  for (const double tick : sx.ticks()) {
    const std::string x = fixed(sx(tick));
    svg += "<line x1=\"" + x + "\" y1=\"" + fixed(y0) + "\" x2=\"" + x + "\" y2=\"" + fixed(y0 + PLOT_H) +
           "\" stroke=\"#e4e4e4\"/><text x=\"" + x + "\" y=\"" + fixed(y0 + PLOT_H + 15) +
           "\" text-anchor=\"middle\">" + tick_text(tick) + "</text>\n";
  }
  for (const double tick : sy.ticks()) {
    const std::string y = fixed(sy(tick));
    svg += "<line x1=\"" + fixed(x0) + "\" y1=\"" + y + "\" x2=\"" + fixed(x0 + PLOT_W) + "\" y2=\"" + y +
           "\" stroke=\"#e4e4e4\"/><text x=\"" + fixed(x0 - 5) + "\" y=\"" + fixed(sy(tick) + 4) +
           "\" text-anchor=\"end\">" + tick_text(tick) + "</text>\n";
  }
  svg += "<text x=\"" + fixed(x0 + PLOT_W / 2) + "\" y=\"" + fixed(y0 + PLOT_H + 36) + "\" text-anchor=\"middle\">" +
         contract::xml_escaped(panel.x.label + (panel.x.log ? ", log scale" : "")) + "</text>\n";
  svg += "<text transform=\"translate(" + fixed(left + 16) + "," + fixed(y0 + PLOT_H / 2) +
         ") rotate(-90)\" text-anchor=\"middle\">" + contract::xml_escaped(panel.y.label + (panel.y.log ? ", log scale" : "")) +
         "</text>\n";
  bool any = false;
  double legend_y = y0 + 8;
  for (std::size_t i = 0; i < panel.series.size(); ++i) {
    const PlotSeries& series = panel.series[i];
    const std::string color = series.color.empty() ? palette_color(i) : series.color;
    const std::string dash = series.dashed ? " stroke-dasharray=\"6,4\"" : "";
    const std::string opacity = series.opacity < 1.0 ? " stroke-opacity=\"" + fixed(series.opacity) + "\"" : "";
    std::string points;
    std::vector<std::array<double, 2>> pixels;
    for (std::size_t k = 0; k < series.points.size(); ++k) {
      const auto& p = series.points[k];
      if (!sx.drawable(p[0]) || !sy.drawable(p[1])) continue;
      pixels.push_back({sx(p[0]), sy(p[1])});
      if (k < series.point_labels.size() && !series.point_labels[k].empty())
        svg += "<text x=\"" + fixed(sx(p[0]) + 6) + "\" y=\"" + fixed(sy(p[1]) - 6) + "\" font-size=\"10\" fill=\"" +
               color + "\">" + contract::xml_escaped(series.point_labels[k]) + "</text>\n";
    }
    any = any || !pixels.empty();
    if (series.line && pixels.size() >= 2) {
      for (const auto& p : pixels) points += fixed(p[0]) + "," + fixed(p[1]) + " ";
      svg += "<polyline fill=\"none\" stroke=\"" + color + "\" stroke-width=\"" + fixed(series.line_width) + "\"" +
             dash + opacity + " stroke-linejoin=\"round\" points=\"" + points + "\"/>\n";
    }
    const std::string fill = series.hollow ? "fill=\"white\" stroke=\"" + color + "\" stroke-width=\"1.5\""
                                           : "fill=\"" + color + "\"";
    if (series.marker_radius > 0)
      for (const auto& p : pixels)
        svg += "<circle cx=\"" + fixed(p[0]) + "\" cy=\"" + fixed(p[1]) + "\" r=\"" + fixed(series.marker_radius) + "\" " +
               fill + "/>\n";
    if (series.label.empty()) continue;
    const double lx = x0 + PLOT_W + LEGEND_GAP;
    if (series.line)
      svg += "<line x1=\"" + fixed(lx) + "\" y1=\"" + fixed(legend_y) + "\" x2=\"" + fixed(lx + 22) + "\" y2=\"" +
             fixed(legend_y) + "\" stroke=\"" + color + "\" stroke-width=\"" + fixed(series.line_width) + "\"" + dash + opacity + "/>\n";
    if (series.marker_radius > 0)
      svg += "<circle cx=\"" + fixed(lx + 11) + "\" cy=\"" + fixed(legend_y) + "\" r=\"" + fixed(series.marker_radius) +
             "\" " + fill + "/>\n";
    svg += "<text x=\"" + fixed(lx + 28) + "\" y=\"" + fixed(legend_y + 4) + "\">" + contract::xml_escaped(series.label) + "</text>\n";
    legend_y += 17;
  }
  if (!any)
    svg += "<text x=\"" + fixed(x0 + PLOT_W / 2) + "\" y=\"" + fixed(y0 + PLOT_H / 2) +
           "\" text-anchor=\"middle\" fill=\"#888\">no point to draw</text>\n";
  return svg;
}

}  // namespace

std::string palette_color(std::size_t i) {
  static const char* const COLORS[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd",
                                       "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"};
  return COLORS[i % (sizeof(COLORS) / sizeof(COLORS[0]))];
}

std::string svg_figure(const std::string& title, const std::vector<PlotPanel>& panels, int columns,
                       const std::string& note) {
  columns = std::max(1, std::min(columns, static_cast<int>(std::max<std::size_t>(panels.size(), 1))));
  const int rows = std::max(1, (static_cast<int>(panels.size()) + columns - 1) / columns);
  // Room for the title (15 px bold: about 9 px a character) and the note (about 7 px).
  const double width = std::max({PANEL_W * columns, LEFT + 9.0 * static_cast<double>(title.size()) + 20,
                                 LEFT + 7.0 * static_cast<double>(note.size()) + 20}),
               height = FIGURE_TOP + PANEL_H * rows + FIGURE_BOTTOM;
  std::string svg = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + fixed(width) + "\" height=\"" + fixed(height) +
                    "\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  svg += "<text x=\"" + fixed(LEFT) + "\" y=\"22\" font-size=\"15\" font-weight=\"bold\">" + contract::xml_escaped(title) + "</text>\n";
  for (std::size_t i = 0; i < panels.size(); ++i) {
    const int row = static_cast<int>(i) / columns, column = static_cast<int>(i) % columns;
    svg += panel_svg(panels[i], PANEL_W * column, FIGURE_TOP + PANEL_H * row);
  }
  if (!note.empty())
    svg += "<text x=\"" + fixed(LEFT) + "\" y=\"" + fixed(height - 8) + "\" fill=\"#666\">" + contract::xml_escaped(note) + "</text>\n";
  svg += "</svg>\n";
  return svg;
}

}  // namespace balloon::bench
