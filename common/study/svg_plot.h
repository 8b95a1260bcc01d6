// A small, dependency-free SVG plotter for the study's figures (forces against time as in the
// paper's Fig. 4, measures per condition as bars with mean +- sd as in Figs. 5-7). The files are
// plain SVG 1.1 that any browser opens.
//
// Units: the plot's width and height are SVG user units (pixels); data values are whatever the
// axis labels say. The axes span the finite data, extended to round tick values (1, 2 or 5 x
// 10^k, about 5 ticks); a constant range is widened by 10 % of its value (1 if it is 0); with no
// finite data an axis spans 0..1. Points with a NaN or infinite coordinate are skipped (the line
// joins their neighbours). All text and colours are XML-escaped.
//
// Invariants the tests rely on: a line plot draws each series that has at least one finite
// point as exactly one <polyline class="series"> (a lone point also gets a <circle>), and
// nothing for a series without one; a bar chart draws each bar with a finite mean as exactly one
// <rect class="bar">; nothing else is a <polyline>, <path> or <rect>. Legends, axes, ticks and
// error bars are <line> and <text>.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace cohaptic {

struct Series {
  std::string label;         ///< legend text; empty = not in the legend
  std::vector<double> x, y;  ///< same length (the shorter length is used otherwise)
  std::string colour;        ///< any SVG colour; empty = the next of a 10-colour palette
  bool markers = false;      ///< a circle at every point
};

struct LinePlot {
  std::string title, x_label, y_label;
  std::vector<Series> series;
  double width = 800, height = 500;
};

struct Bar {
  std::string category;  ///< label under the bar
  double mean = 0;       ///< bar height (from 0); NaN = no bar
  double sd = 0;         ///< error bar mean +- sd; NaN or 0 = none
  std::string colour;    ///< empty = palette colour of the bar's index
};

struct BarChart {
  std::string title, x_label, y_label;
  std::vector<Bar> bars;
  double width = 800, height = 500;
};

using Plot = std::variant<LinePlot, BarChart>;

/// The SVG document. Throws Error if width or height is not a positive number.
std::string render_svg(const Plot& plot);

/// render_svg() written atomically to `path` (AtomicFile). Throws Error if it cannot be written.
void write_svg(const std::filesystem::path& path, const Plot& plot);

/// The index-th colour (cyclic) of the plots' 10-colour palette, as an SVG colour.
std::string palette_colour(std::size_t index);

/// Text made safe for XML character data and attribute values: & < > " ' become entities and
/// control characters other than tab, line feed and carriage return are dropped.
std::string xml_escape(std::string_view text);

/// Round tick values covering [lo, hi]: multiples of a step 1, 2 or 5 x 10^k chosen for about
/// `target` intervals, from floor(lo / step) step to ceil(hi / step) step. Requires finite
/// lo < hi; returns {lo, hi} if no such step is representable.
std::vector<double> nice_ticks(double lo, double hi, int target = 5);

}  // namespace cohaptic
