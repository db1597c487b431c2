#include "contract/curve_files.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <vector>

#include "contract/xml_text.hpp"

namespace balloon::contract {
namespace {

namespace v1 = balloon::v1;

std::string number(double value) {
  if (!std::isfinite(value)) return "";
  char buffer[32];
  return std::string(buffer, std::to_chars(buffer, buffer + sizeof(buffer), value).ptr);
}

std::string fixed(double value, const char* pattern = "%.1f") {
  char buffer[48];
  std::snprintf(buffer, sizeof(buffer), pattern, value);
  return buffer;
}

/// 1, 2, 5 times a power of ten: the tick step that gives about `count` ticks over `span`.
double nice_step(double span, int count) {
  const double raw = span / count;
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  for (const double m : {1.0, 2.0, 5.0})
    if (m * power >= raw) return m * power;
  return 10.0 * power;
}

constexpr double WIDTH = 760, HEIGHT = 480, LEFT = 70, RIGHT = 30, TOP = 40, BOTTOM = 60;

}  // namespace

std::string curve_csv(const v1::CurveReport& report) {
  std::string csv = "volume_ratio,pressure_kpa,mean_stretch,max_stretch,unstable_modes,converged\n";
  for (const v1::CurvePointReport& point : report.points()) {
    csv += (point.has_volume_ratio() ? number(point.volume_ratio()) : "") + ",";
    csv += (point.has_pressure_kpa() ? number(point.pressure_kpa()) : "") + ",";
    csv += (point.has_mean_stretch() ? number(point.mean_stretch()) : "") + ",";
    csv += (point.has_max_stretch() ? number(point.max_stretch()) : "") + ",";
    csv += (point.has_unstable_modes() ? number(point.unstable_modes()) : "") + ",";
    csv += point.converged() ? "true\n" : "false\n";
  }
  return csv;
}

std::string curve_svg(const v1::CurveReport& report) {
  struct Sample {
    double ratio, pressure;
    bool unstable;
  };
  std::vector<std::vector<Sample>> runs(1);  // converged stretches of the path, broken at unconverged points
  for (const v1::CurvePointReport& point : report.points()) {
    const bool usable = point.converged() && point.has_volume_ratio() && point.has_pressure_kpa() &&
                        std::isfinite(point.volume_ratio()) && point.volume_ratio() > 0 &&
                        std::isfinite(point.pressure_kpa());
    if (!usable) {
      if (!runs.back().empty()) runs.emplace_back();
      continue;
    }
    runs.back().push_back({point.volume_ratio(), point.pressure_kpa(),
                           point.has_unstable_modes() && point.unstable_modes() > 0});
  }
  double x_min = INFINITY, x_max = -INFINITY, y_min = 0.0, y_max = -INFINITY;
  for (const auto& run : runs)
    for (const Sample& s : run) {
      x_min = std::min(x_min, s.ratio);
      x_max = std::max(x_max, s.ratio);
      y_min = std::min(y_min, s.pressure);
      y_max = std::max(y_max, s.pressure);
    }
  const bool empty = !(x_min <= x_max);
  if (empty) {
    x_min = report.control() == "volume_ratio" && report.range_from() > 0 ? report.range_from() : 1.0;
    x_max = report.control() == "volume_ratio" && report.range_to() > x_min ? report.range_to() : 10.0 * x_min;
    y_max = 1.0;
  }
  if (!(x_max > x_min * 1.0001)) x_max = x_min * 1.1;
  if (!(y_max > y_min)) y_max = y_min + 1.0;
  const double y_step = nice_step(y_max - y_min, 6);
  y_max = std::ceil(y_max * 1.05 / y_step) * y_step;
  y_min = std::floor(y_min / y_step) * y_step;
  const double plot_w = WIDTH - LEFT - RIGHT, plot_h = HEIGHT - TOP - BOTTOM;
  const double lx_min = std::log10(x_min), lx_max = std::log10(x_max);
  auto px = [&](double ratio) { return LEFT + plot_w * (std::log10(ratio) - lx_min) / (lx_max - lx_min); };
  auto py = [&](double pressure) { return TOP + plot_h * (1.0 - (pressure - y_min) / (y_max - y_min)); };

  std::string svg = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + fixed(WIDTH, "%.0f") + "\" height=\"" +
                    fixed(HEIGHT, "%.0f") + "\" font-family=\"sans-serif\" font-size=\"12\">\n";
  svg += "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  std::string title = "Pressure-volume curve: " + report.material();
  if (!report.material_name().empty()) title += " (" + report.material_name() + ")";
  title += ", h = " + number(report.thickness_mm()) + " mm, " + std::to_string(report.vertices()) + " vertices";
  svg += "<text x=\"" + fixed(LEFT) + "\" y=\"22\" font-weight=\"bold\">" + xml_escaped(title) + "</text>\n";
  svg += "<rect x=\"" + fixed(LEFT) + "\" y=\"" + fixed(TOP) + "\" width=\"" + fixed(plot_w) + "\" height=\"" +
         fixed(plot_h) + "\" fill=\"none\" stroke=\"#888\"/>\n";
  // Log ticks at 1, 2, 5 per decade (every decade only when they would crowd).
  const bool crowded = lx_max - lx_min > 4.0;
  for (int decade = static_cast<int>(std::floor(lx_min)); decade <= static_cast<int>(std::ceil(lx_max)); ++decade)
    for (const double m : {1.0, 2.0, 5.0}) {
      if (crowded && m != 1.0) continue;
      const double tick = m * std::pow(10.0, decade);
      if (tick < x_min * 0.9999 || tick > x_max * 1.0001) continue;
      const std::string x = fixed(px(tick));
      svg += "<line x1=\"" + x + "\" y1=\"" + fixed(TOP) + "\" x2=\"" + x + "\" y2=\"" + fixed(TOP + plot_h) +
             "\" stroke=\"#eee\"/>\n";
      svg += "<text x=\"" + x + "\" y=\"" + fixed(TOP + plot_h + 16) + "\" text-anchor=\"middle\">" + number(tick) +
             "</text>\n";
    }
  for (double tick = y_min; tick <= y_max + 1e-9 * y_step; tick += y_step) {
    const std::string y = fixed(py(tick));
    svg += "<line x1=\"" + fixed(LEFT) + "\" y1=\"" + y + "\" x2=\"" + fixed(LEFT + plot_w) + "\" y2=\"" + y +
           "\" stroke=\"#eee\"/>\n";
    svg += "<text x=\"" + fixed(LEFT - 6) + "\" y=\"" + fixed(py(tick) + 4) + "\" text-anchor=\"end\">" +
           number(std::round(tick / y_step * 1e6) / 1e6 * y_step) + "</text>\n";
  }
  svg += "<text x=\"" + fixed(LEFT + plot_w / 2) + "\" y=\"" + fixed(HEIGHT - 20) +
         "\" text-anchor=\"middle\">volume ratio V/V0 (log scale)</text>\n";
  svg += "<text transform=\"translate(18," + fixed(TOP + plot_h / 2) +
         ") rotate(-90)\" text-anchor=\"middle\">pressure (kPa)</text>\n";
  if (empty)
    svg += "<text x=\"" + fixed(LEFT + plot_w / 2) + "\" y=\"" + fixed(TOP + plot_h / 2) +
           "\" text-anchor=\"middle\">no converged point</text>\n";
  for (const auto& run : runs) {
    if (run.size() >= 2) {
      svg += "<polyline fill=\"none\" stroke=\"#1f77b4\" stroke-width=\"2\" points=\"";
      for (const Sample& s : run) svg += fixed(px(s.ratio)) + "," + fixed(py(s.pressure)) + " ";
      svg += "\"/>\n";
    }
    for (const Sample& s : run)
      svg += "<circle cx=\"" + fixed(px(s.ratio)) + "\" cy=\"" + fixed(py(s.pressure)) + "\" r=\"3\" " +
             (s.unstable ? "fill=\"white\" stroke=\"#d62728\"" : "fill=\"#1f77b4\"") + "/>\n";
  }
  for (const v1::CurveExtremumReport& extremum : report.extrema()) {
    if (!(extremum.volume_ratio() > 0) || !std::isfinite(extremum.pressure_kpa())) continue;
    const bool maximum = extremum.kind() == "maximum";
    const double x = px(std::clamp(extremum.volume_ratio(), x_min, x_max)), y = py(extremum.pressure_kpa());
    const char* color = maximum ? "#d62728" : "#2ca02c";
    // A triangle pointing at the extremum from above (maximum) or below (minimum).
    const double d = maximum ? -1.0 : 1.0;
    svg += "<path class=\"" + std::string(maximum ? "pressure-maximum" : "pressure-minimum") + "\" d=\"M" + fixed(x) +
           "," + fixed(y + 4 * d) + " L" + fixed(x - 6) + "," + fixed(y + 14 * d) + " L" + fixed(x + 6) + "," +
           fixed(y + 14 * d) + " Z\" fill=\"" + color + "\"/>\n";
    svg += "<text x=\"" + fixed(x) + "\" y=\"" + fixed(y + (maximum ? -18 : 26)) + "\" text-anchor=\"middle\" fill=\"" +
           color + "\">" + (maximum ? "max " : "min ") + fixed(extremum.pressure_kpa(), "%.3g") + " kPa at V/V0 " +
           fixed(extremum.volume_ratio(), "%.3g") + "</text>\n";
  }
  svg += "<text x=\"" + fixed(LEFT + plot_w) + "\" y=\"" + fixed(HEIGHT - 4) +
         "\" text-anchor=\"end\" fill=\"#666\">filled: stable; hollow red: unstable modes; triangles: pressure extrema</text>\n";
  svg += "</svg>\n";
  return svg;
}

}  // namespace balloon::contract
