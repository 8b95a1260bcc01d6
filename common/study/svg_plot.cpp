#include "common/study/svg_plot.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "common/util/atomic_file.h"
#include "common/util/error.h"

namespace cohaptic {
namespace {

constexpr double kLeft = 80, kTop = 50, kBottom = 60, kRight = 25;
constexpr double kCharWidth = 7;  // rough width of a 12 px sans-serif character

struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();

  void add(double v) {
    if (!std::isfinite(v)) return;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
};

// A data range made drawable: empty -> 0..1, constant -> widened; then extended to round ticks.
struct Axis {
  double lo = 0, hi = 1;
  std::vector<double> ticks;

  explicit Axis(Range r) {
    if (!(r.lo <= r.hi)) r = {0, 1};
    if (r.lo == r.hi) {
      const double pad = r.lo != 0 ? 0.1 * std::abs(r.lo) : 1;
      r = {r.lo - pad, r.hi + pad};
    }
    ticks = nice_ticks(r.lo, r.hi);
    lo = std::min(r.lo, ticks.front());
    hi = std::max(r.hi, ticks.back());
    if (!(hi > lo) || !std::isfinite(hi - lo)) {  // beyond double's range: give up on scaling well
      lo = 0;
      hi = 1;
      ticks = {0, 1};
    }
  }
  // Fraction of the way from lo to hi.
  double frac(double v) const { return (v - lo) / (hi - lo); }
};

std::string tick_label(double v, const std::vector<double>& ticks) {
  const double step = ticks.size() > 1 ? std::abs(ticks[1] - ticks[0]) : std::abs(v);
  if (v == 0 || !(step > 0)) return "0";
  const double magnitude = std::max(std::abs(ticks.front()), std::abs(ticks.back()));
  if (magnitude >= 1e7 || magnitude < 1e-4) return fmt::format("{:.3g}", v);
  const int decimals = std::max(0, -static_cast<int>(std::floor(std::log10(step) + 1e-9)));
  return fmt::format("{:.{}f}", v, decimals);
}

std::string colour_of(const std::string& colour, std::size_t index) {
  return colour.empty() ? palette_colour(index) : colour;
}

class Canvas {
 public:
  Canvas(double width, double height) : width_(width), height_(height) {
    if (!(width > 0) || !(height > 0) || !std::isfinite(width) || !std::isfinite(height))
      throw Error(fmt::format("a plot must have a positive size, got {} x {}", width, height));
    out_ += fmt::format(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
        "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" width=\"{0:g}\" "
        "height=\"{1:g}\" "
        "viewBox=\"0 0 {0:g} {1:g}\" font-family=\"sans-serif\" font-size=\"12\" "
        "style=\"background:#ffffff\">\n",
        width, height);
  }

  void line(double x1, double y1, double x2, double y2, std::string_view colour,
            double stroke_width = 1) {
    out_ += fmt::format(
        "<line x1=\"{:.2f}\" y1=\"{:.2f}\" x2=\"{:.2f}\" y2=\"{:.2f}\" stroke=\"{}\" "
        "stroke-width=\"{:g}\"/>\n",
        x1, y1, x2, y2, xml_escape(colour), stroke_width);
  }
  void text(double x, double y, std::string_view content, std::string_view anchor,
            double rotate = 0, std::string_view extra = {}) {
    std::string transform;
    if (rotate != 0)
      transform = fmt::format(" transform=\"rotate({:g} {:.2f} {:.2f})\"", rotate, x, y);
    out_ += fmt::format("<text x=\"{:.2f}\" y=\"{:.2f}\" text-anchor=\"{}\"{}{}>{}</text>\n", x, y,
                        anchor, transform, extra, xml_escape(content));
  }
  void raw(std::string_view s) { out_ += s; }
  std::string finish() { return out_ + "</svg>\n"; }

  double width() const { return width_; }
  double height() const { return height_; }

 private:
  double width_, height_;
  std::string out_;
};

// Title, axis labels, grid, ticks and axes around the plot area [x0, x1] x [y0, y1] (pixels).
void draw_frame(Canvas& c, double x0, double x1, double y0, double y1, const std::string& title,
                const std::string& x_label, const std::string& y_label, const Axis* x_axis,
                const Axis& y_axis) {
  if (!title.empty()) c.text(c.width() / 2, kTop / 2 + 5, title, "middle", 0, " font-size=\"16\"");
  for (double t : y_axis.ticks) {
    const double y = y1 - y_axis.frac(t) * (y1 - y0);
    c.line(x0, y, x1, y, "#e0e0e0");
    c.line(x0 - 5, y, x0, y, "#000000");
    c.text(x0 - 8, y + 4, tick_label(t, y_axis.ticks), "end");
  }
  if (x_axis != nullptr)
    for (double t : x_axis->ticks) {
      const double x = x0 + x_axis->frac(t) * (x1 - x0);
      c.line(x, y0, x, y1, "#e0e0e0");
      c.line(x, y1, x, y1 + 5, "#000000");
      c.text(x, y1 + 18, tick_label(t, x_axis->ticks), "middle");
    }
  c.line(x0, y1, x1, y1, "#000000");
  c.line(x0, y0, x0, y1, "#000000");
  if (!x_label.empty()) c.text((x0 + x1) / 2, c.height() - 15, x_label, "middle");
  if (!y_label.empty()) c.text(20, (y0 + y1) / 2, y_label, "middle", -90);
}

std::string render(const LinePlot& plot) {
  Canvas c(plot.width, plot.height);
  Range xr, yr;
  std::size_t legend_chars = 0;
  for (const Series& s : plot.series) {
    const std::size_t n = std::min(s.x.size(), s.y.size());
    for (std::size_t i = 0; i < n; ++i)
      if (std::isfinite(s.x[i]) && std::isfinite(s.y[i])) {
        xr.add(s.x[i]);
        yr.add(s.y[i]);
      }
    legend_chars = std::max(legend_chars, s.label.size());
  }
  const Axis x_axis(xr), y_axis(yr);
  const double legend_width =
      legend_chars > 0 ? 40 + kCharWidth * static_cast<double>(legend_chars) : 0;
  const double x0 = kLeft, x1 = std::max(x0 + 10, plot.width - kRight - legend_width);
  const double y0 = kTop, y1 = std::max(y0 + 10, plot.height - kBottom);
  draw_frame(c, x0, x1, y0, y1, plot.title, plot.x_label, plot.y_label, &x_axis, y_axis);

  double legend_y = y0 + 10;
  for (std::size_t index = 0; index < plot.series.size(); ++index) {
    const Series& s = plot.series[index];
    const std::string colour = xml_escape(colour_of(s.colour, index));
    std::string points;
    std::vector<std::pair<double, double>> pixels;
    const std::size_t n = std::min(s.x.size(), s.y.size());
    for (std::size_t i = 0; i < n; ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      const double px = x0 + x_axis.frac(s.x[i]) * (x1 - x0),
                   py = y1 - y_axis.frac(s.y[i]) * (y1 - y0);
      points += fmt::format("{}{:.2f},{:.2f}", points.empty() ? "" : " ", px, py);
      pixels.emplace_back(px, py);
    }
    if (!pixels.empty()) {
      c.raw(
          fmt::format("<polyline class=\"series\" fill=\"none\" stroke=\"{}\" stroke-width=\"1.5\" "
                      "stroke-linejoin=\"round\" points=\"{}\"/>\n",
                      colour, points));
      if (s.markers || pixels.size() == 1)
        for (const auto& [px, py] : pixels)
          c.raw(fmt::format("<circle cx=\"{:.2f}\" cy=\"{:.2f}\" r=\"3\" fill=\"{}\"/>\n", px, py,
                            colour));
    }
    if (!s.label.empty()) {
      c.line(x1 + 10, legend_y, x1 + 30, legend_y, colour, 2);
      c.text(x1 + 35, legend_y + 4, s.label, "start");
      legend_y += 18;
    }
  }
  return c.finish();
}

std::string render(const BarChart& chart) {
  Canvas c(chart.width, chart.height);
  Range yr;
  yr.add(0);
  for (const Bar& bar : chart.bars) {
    yr.add(bar.mean);
    if (std::isfinite(bar.mean) && std::isfinite(bar.sd)) {
      yr.add(bar.mean + std::abs(bar.sd));
      yr.add(bar.mean - std::abs(bar.sd));
    }
  }
  const Axis y_axis(yr);
  const double x0 = kLeft, x1 = std::max(x0 + 10, chart.width - kRight);
  const double y0 = kTop, y1 = std::max(y0 + 10, chart.height - kBottom);
  draw_frame(c, x0, x1, y0, y1, chart.title, chart.x_label, chart.y_label, nullptr, y_axis);

  const double slot = (x1 - x0) / static_cast<double>(std::max<std::size_t>(chart.bars.size(), 1));
  const double zero_y = y1 - y_axis.frac(0) * (y1 - y0);
  if (zero_y < y1) c.line(x0, zero_y, x1, zero_y, "#000000");  // the bars' base line
  for (std::size_t i = 0; i < chart.bars.size(); ++i) {
    const Bar& bar = chart.bars[i];
    const double centre = x0 + (static_cast<double>(i) + 0.5) * slot;
    const bool rotate = kCharWidth * static_cast<double>(bar.category.size()) > slot;
    c.text(centre, y1 + 18, bar.category, rotate ? "end" : "middle", rotate ? -30 : 0);
    if (!std::isfinite(bar.mean)) continue;
    const double top = y1 - y_axis.frac(bar.mean) * (y1 - y0);
    const double half = 0.3 * slot;
    c.raw(
        fmt::format("<rect class=\"bar\" x=\"{:.2f}\" y=\"{:.2f}\" width=\"{:.2f}\" "
                    "height=\"{:.2f}\" fill=\"{}\"/>\n",
                    centre - half, std::min(top, zero_y), 2 * half, std::abs(zero_y - top),
                    xml_escape(colour_of(bar.colour, i))));
    if (std::isfinite(bar.sd) && bar.sd != 0) {
      const double sd = std::abs(bar.sd);
      const double hi = y1 - y_axis.frac(bar.mean + sd) * (y1 - y0),
                   lo = y1 - y_axis.frac(bar.mean - sd) * (y1 - y0);
      const double cap = 0.25 * half;
      c.line(centre, hi, centre, lo, "#000000", 1.5);
      c.line(centre - cap, hi, centre + cap, hi, "#000000", 1.5);
      c.line(centre - cap, lo, centre + cap, lo, "#000000", 1.5);
    }
  }
  return c.finish();
}

}  // namespace

std::string palette_colour(std::size_t index) {
  static constexpr std::array<const char*, 10> kPalette = {
      "#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd",
      "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"};
  return kPalette[index % kPalette.size()];
}

std::string xml_escape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (char ch : text) {
    switch (ch) {
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
      case '\'':
        out += "&apos;";
        break;
      default:
        if (static_cast<unsigned char>(ch) < 0x20 && ch != '\t' && ch != '\n' && ch != '\r') break;
        out += ch;
    }
  }
  return out;
}

std::vector<double> nice_ticks(double lo, double hi, int target) {
  const double span = hi - lo;
  if (!(span > 0) || !std::isfinite(span) || target < 1) return {lo, hi};
  const double raw = span / target;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  const double r = raw / magnitude;
  const double step = (r < 1.5 ? 1 : r < 3 ? 2 : r < 7 ? 5 : 10) * magnitude;
  if (!(step > 0) || !std::isfinite(step)) return {lo, hi};
  const double first = std::floor(lo / step), last = std::ceil(hi / step);
  if (!std::isfinite(first) || !std::isfinite(last) || last - first > 100 || last - first < 1 ||
      std::max(std::abs(first), std::abs(last)) > 1e15)  // first + j would lose digits
    return {lo, hi};
  const auto count = static_cast<int>(last - first);
  std::vector<double> ticks;
  for (int j = 0; j <= count; ++j) ticks.push_back((first + j) * step);
  return ticks;
}

std::string render_svg(const Plot& plot) {
  return std::visit([](const auto& p) { return render(p); }, plot);
}

void write_svg(const std::filesystem::path& path, const Plot& plot) {
  const std::string svg = render_svg(plot);
  AtomicFile file(path);
  file.write(svg);
  file.commit();
}

}  // namespace cohaptic
