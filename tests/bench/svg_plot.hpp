#pragma once
/// The benches' SVG plots: panels of x-y series on linear or log axes, with grid, ticks, axis labels and a
/// legend. Plain text out; the caller writes the file.
#include <array>
#include <cstddef>
#include <string>
#include <vector>

namespace balloon::bench {

/// One axis of a panel.
struct PlotAxis {
  std::string label;  ///< the quantity and its unit, e.g. "time (s)"
  bool log = false;   ///< log10 scale; points with a value <= 0 on this axis are left out
};

/// One data series: a polyline and/or markers, and its legend entry.
struct PlotSeries {
  std::string label;                          ///< legend text; empty: no legend entry
  std::vector<std::array<double, 2>> points;  ///< (x, y) in axis units, drawn in this order
  std::string color;                          ///< SVG colour; empty: palette_color(index in the panel)
  bool line = true;                           ///< join consecutive points
  bool dashed = false;                        ///< dashed line
  double line_width = 2.0;                    ///< px
  double opacity = 1.0;                       ///< of the line (0 to 1), e.g. a wide pale band under other series
  double marker_radius = 0.0;                 ///< marker size (px); 0 draws none
  bool hollow = false;                        ///< rings instead of dots
  std::vector<std::string> point_labels;      ///< optional text beside each point (same order; may be shorter)
};

/// One plot: a title, two axes and its series (the axis ranges fit the series' points).
struct PlotPanel {
  std::string title;
  PlotAxis x, y;
  std::vector<PlotSeries> series;
};

/// Colour i of the palette (matplotlib's tab10, cycling).
std::string palette_color(std::size_t i);

/// An SVG figure: `title` at the top, the panels in rows of `columns` (each 660 x 360 px, its legend to
/// the right of its plot area; wider when the title or note needs it), and `note` (may be empty) as a grey
/// line at the bottom. Series are drawn in order (the first one lowest). A panel with no
/// drawable point says so in its plot area.
std::string svg_figure(const std::string& title, const std::vector<PlotPanel>& panels, int columns = 1,
                       const std::string& note = "");

}  // namespace balloon::bench
