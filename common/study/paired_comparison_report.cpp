#include "common/study/paired_comparison_report.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <system_error>

#include "common/study/svg_plot.h"
#include "common/util/atomic_file.h"
#include "common/util/csv.h"
#include "common/util/error.h"

namespace cohaptic {
namespace {

// svg_plot's palette, so that a condition keeps its colour between the figures. (File-local
// names here differ from svg_plot.cpp's: a unity build may compile the two as one unit.)
// Vertical layout of the figure, in pixels: the title and question at the top, the label rows,
// the scale line, its tick labels, then the two yardsticks.
constexpr double kTitleBaseline = 24, kQuestionBaseline = 44, kHeaderBottom = 52;
constexpr double kRowHeight = kScaleLineFontSize + 6;  // > a label box's height (1.25 font sizes)
constexpr double kConditionTickHalf = 7;
constexpr double kFirstRowAboveLine = kConditionTickHalf + 5;  // row 0's baseline above the line
constexpr double kAxisLabelBelowLine = 20;
constexpr double kFirstYardstickBelowLine = 44, kYardstickSpacing = 20, kBottomMargin = 20;
constexpr double kMinimumSideMargin = 70;

// Where each label sits: its centre, its width and its row (0 nearest the line).
struct LabelPlacement {
  double centre = 0, width = 0;
  int row = 0;
};

// Labels centred over their ticks (pulled inside the canvas if they would stick out), then
// put on the lowest row where they clear the labels already there. Taking labels in order of
// their left edges makes this the greedy interval colouring, which uses the fewest rows; and
// as a row's labels do not overlap, the last one placed also ends furthest right.
std::vector<LabelPlacement> place_labels(const std::vector<std::string>& names,
                                         const std::vector<double>& tick_x, double canvas_width) {
  std::vector<LabelPlacement> labels(names.size());
  for (std::size_t i = 0; i < names.size(); ++i) {
    const double width = scale_line_label_width(names[i]);
    double centre = tick_x[i];
    if (canvas_width >= width + 4)
      centre = std::clamp(centre, width / 2 + 2, canvas_width - width / 2 - 2);
    labels[i] = {centre, width, 0};
  }
  std::vector<std::size_t> order(names.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return labels[a].centre - labels[a].width / 2 < labels[b].centre - labels[b].width / 2;
  });
  std::vector<double> row_right_end;
  for (std::size_t i : order) {
    const double left = labels[i].centre - labels[i].width / 2;
    std::size_t row = 0;
    while (row < row_right_end.size() && row_right_end[row] + kScaleLineLabelGap > left) ++row;
    if (row == row_right_end.size()) row_right_end.push_back(0);
    row_right_end[row] = labels[i].centre + labels[i].width / 2;
    labels[i].row = static_cast<int>(row);
  }
  return labels;
}

// "+0.5", "0", "-1.5": as many decimals as the tick step needs, the sign always shown, since
// the sign says which way the question leans.
std::string axis_label(double value, double step) {
  if (value == 0) return "0";
  const int decimals =
      step > 0 ? std::max(0, -static_cast<int>(std::floor(std::log10(step) + 1e-9))) : 3;
  return fmt::format("{:+.{}f}", value, decimals);
}

std::string yardstick_label(const char* level, double yardstick) {
  return fmt::format("Y({}) = {:.3f}", level, yardstick);
}

void check_figure(const ScaleLineFigure& figure) {
  if (!(figure.width > 0) || !(figure.height > 0) || !std::isfinite(figure.width) ||
      !std::isfinite(figure.height))
    throw Error(fmt::format("scale line figure: the size must be positive, got {} x {}",
                            figure.width, figure.height));
  if (figure.names.size() != figure.scale.size())
    throw Error(fmt::format("scale line figure: {} names for {} scale values", figure.names.size(),
                            figure.scale.size()));
  for (std::size_t i = 0; i < figure.scale.size(); ++i)
    if (!std::isfinite(figure.scale[i]))
      throw Error(
          fmt::format("scale line figure: the scale value of {} is not a number", figure.names[i]));
  for (const double yardstick : {figure.yardstick_05, figure.yardstick_01})
    if (!std::isfinite(yardstick) || yardstick < 0)
      throw Error(
          fmt::format("scale line figure: a yardstick must be a finite length, got {}", yardstick));
}

class SvgWriter {
 public:
  void line(std::string_view css_class, double x1, double y1, double x2, double y2,
            std::string_view colour, double stroke_width) {
    out += fmt::format(
        "<line class=\"{}\" x1=\"{:.2f}\" y1=\"{:.2f}\" x2=\"{:.2f}\" y2=\"{:.2f}\" stroke=\"{}\" "
        "stroke-width=\"{:g}\"/>\n",
        css_class, x1, y1, x2, y2, xml_escape(colour), stroke_width);
  }
  void text(std::string_view css_class, double x, double y, std::string_view content,
            std::string_view anchor, std::string_view extra = {}) {
    out +=
        fmt::format("<text class=\"{}\" x=\"{:.2f}\" y=\"{:.2f}\" text-anchor=\"{}\"{}>{}</text>\n",
                    css_class, x, y, anchor, extra, xml_escape(content));
  }
  std::string out;
};

void check_names(std::size_t names, const PairedComparisonAnalysis& analysis) {
  if (names != analysis.scale.size())
    throw Error(fmt::format("paired comparison report: {} condition names for {} conditions", names,
                            analysis.scale.size()));
}

// 1 for the highest scale value; equal values share the better rank ("1224").
std::vector<int> ranks_of(const std::vector<double>& scale) {
  std::vector<int> ranks;
  for (double value : scale)
    ranks.push_back(1 +
                    static_cast<int>(std::count_if(scale.begin(), scale.end(),
                                                   [&](double other) { return other > value; })));
  return ranks;
}

std::string csv_number(double value) {
  return std::isnan(value) ? std::string() : fmt::format("{:.9g}", value);
}

struct NamedSource {
  std::string name;
  const VarianceSource* source;
};

std::vector<NamedSource> anova_lines(const PairedComparisonAnalysis& a,
                                     const std::vector<FactorEffect>& factors) {
  std::vector<NamedSource> lines{{"main_effect", &a.main_effect},
                                 {"main_effect_x_subject", &a.main_by_subject},
                                 {"combination", &a.combination},
                                 {"error", &a.error},
                                 {"total", &a.total}};
  for (const FactorEffect& factor : factors)
    lines.push_back({"factor:" + factor.name, &factor.source});
  return lines;
}

std::string significance_marker(double p) { return p < 0.01 ? "**" : p < 0.05 ? "*" : ""; }

// A table cell: blank for NaN (the error and total lines have no F test).
std::string table_cell(double value, const char* format_spec) {
  return std::isnan(value) ? std::string() : fmt::format(fmt::runtime(format_spec), value);
}

}  // namespace

double scale_line_label_width(std::string_view text) {
  // UTF-8 continuation bytes (10xxxxxx) do not start a character.
  const auto characters = std::count_if(text.begin(), text.end(), [](char ch) {
    return (static_cast<unsigned char>(ch) & 0xC0) != 0x80;
  });
  return kScaleLineCharWidth * static_cast<double>(characters);
}

std::string render_scale_line_svg(const ScaleLineFigure& figure) {
  check_figure(figure);
  const double longest_yardstick = std::max(figure.yardstick_05, figure.yardstick_01);

  // The axis: symmetric about 0, round ticks, holding every scale value and, drawn from its
  // left end, the longer yardstick.
  double reach = longest_yardstick / 2;
  for (double value : figure.scale) reach = std::max(reach, std::abs(value));
  if (!(reach > 0)) reach = 1;
  const std::vector<double> ticks = nice_ticks(-reach, reach, 6);
  const double lo = std::min(-reach, ticks.front()), hi = std::max(reach, ticks.back());
  const double step = ticks.size() > 1 ? ticks[1] - ticks[0] : hi - lo;

  // The yardsticks' labels sit left of the axis: both margins make room for them, so the
  // axis stays centred under the title.
  const std::string label_05 = yardstick_label("0.05", figure.yardstick_05);
  const std::string label_01 = yardstick_label("0.01", figure.yardstick_01);
  const double side_margin =
      std::max(kMinimumSideMargin,
               20 + std::max(scale_line_label_width(label_05), scale_line_label_width(label_01)));
  const double x0 = side_margin, x1 = std::max(x0 + 10, figure.width - side_margin);
  const auto x_of = [&](double grades) { return x0 + (grades - lo) / (hi - lo) * (x1 - x0); };

  std::vector<double> tick_x;
  for (double value : figure.scale) tick_x.push_back(x_of(value));
  const std::vector<LabelPlacement> labels = place_labels(figure.names, tick_x, figure.width);
  int rows = 1;
  for (const LabelPlacement& label : labels) rows = std::max(rows, label.row + 1);

  // The line as high as the label rows allow, the whole block centred in what height is left.
  const double lowest_line =
      kHeaderBottom + kScaleLineFontSize + kFirstRowAboveLine + (rows - 1) * kRowHeight;
  const double below_line = kFirstYardstickBelowLine + kYardstickSpacing + kBottomMargin;
  const double spare = std::max(0.0, figure.height - lowest_line - below_line);
  const double line_y = lowest_line + spare / 2;
  const double height = std::max(figure.height, lowest_line + below_line);

  SvgWriter svg;
  svg.out = fmt::format(
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" width=\"{0:g}\" height=\"{1:g}\" "
      "viewBox=\"0 0 {0:g} {1:g}\" font-family=\"sans-serif\" font-size=\"{2:g}\" "
      "style=\"background:#ffffff\">\n",
      figure.width, height, kScaleLineFontSize);
  if (!figure.title.empty())
    svg.text("title", figure.width / 2, kTitleBaseline, figure.title, "middle",
             " font-size=\"16\"");
  if (!figure.question.empty())
    svg.text("question", figure.width / 2, kQuestionBaseline, figure.question, "middle",
             " fill=\"#444444\" xml:space=\"preserve\"");  // the question may space its parts apart

  svg.line("scale-line", x0, line_y, x1, line_y, "#000000", 1.5);
  for (double t : ticks) {
    const double x = x_of(t);
    svg.line("axis-tick", x, line_y, x, line_y + 5, "#000000", 1);
    svg.text("axis-label", x, line_y + kAxisLabelBelowLine, axis_label(t, step), "middle");
  }
  svg.text("axis-unit", x1 + 8, line_y + 4, "grades", "start", " fill=\"#444444\"");

  for (std::size_t i = 0; i < figure.scale.size(); ++i) {
    const std::string colour = palette_colour(i);
    svg.line("condition", tick_x[i], line_y - kConditionTickHalf, tick_x[i],
             line_y + kConditionTickHalf, colour, 2);
    const double baseline = line_y - kFirstRowAboveLine - labels[i].row * kRowHeight;
    svg.text("condition-label", labels[i].centre, baseline, figure.names[i], "middle",
             fmt::format(" fill=\"{}\"", colour));
  }

  const struct {
    const std::string& label;
    double length;
  } yardsticks[] = {{label_05, figure.yardstick_05}, {label_01, figure.yardstick_01}};
  double y = line_y + kFirstYardstickBelowLine;
  for (const auto& yardstick : yardsticks) {
    // From the axis's left end, in grades of the axis: a distance between two ticks above
    // longer than the bar is a difference at that level.
    const double end = x0 + (x_of(yardstick.length) - x_of(0));
    svg.line("yardstick", x0, y, end, y, "#000000", 3);
    svg.line("yardstick-end", x0, y - 5, x0, y + 5, "#000000", 1);
    svg.line("yardstick-end", end, y - 5, end, y + 5, "#000000", 1);
    svg.text("yardstick-label", x0 - 10, y + 4, yardstick.label, "end");
    y += kYardstickSpacing;
  }
  return svg.out + "</svg>\n";
}

void write_scale_line_svg(const std::filesystem::path& path, const ScaleLineFigure& figure) {
  const std::string svg = render_scale_line_svg(figure);
  AtomicFile file(path);
  file.write(svg);
  file.commit();
}

void write_analysis_csv(const std::filesystem::path& dir, const PairedComparisonAnalysis& analysis,
                        const std::vector<std::string>& condition_names,
                        const std::vector<FactorEffect>& factors) {
  check_names(condition_names.size(), analysis);
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error)
    throw Error(fmt::format("cannot make the directory {}: {}", dir.string(), error.message()));

  {
    const std::vector<int> ranks = ranks_of(analysis.scale);
    AtomicFile file(dir / "scale.csv");
    file.write("condition,scale_value,rank\n");
    for (std::size_t i = 0; i < analysis.scale.size(); ++i)
      file.print("{},{},{}\n", csv_field(condition_names[i]), csv_number(analysis.scale[i]),
                 ranks[i]);
    file.commit();
  }
  {
    AtomicFile file(dir / "anova.csv");
    file.write("source,sum_of_squares,degrees_of_freedom,mean_square,f,p\n");
    for (const NamedSource& line : anova_lines(analysis, factors)) {
      const VarianceSource& s = *line.source;
      file.print("{},{},{},{},{},{}\n", csv_field(line.name), csv_number(s.sum_of_squares),
                 csv_number(s.degrees_of_freedom), csv_number(s.mean_square), csv_number(s.f),
                 csv_number(s.p));
    }
    file.commit();
  }
  {
    AtomicFile file(dir / "yardsticks.csv");
    file.write("level,yardstick\n");
    file.print("0.05,{}\n0.01,{}\n", csv_number(analysis.yardstick_05),
               csv_number(analysis.yardstick_01));
    file.commit();
  }
  {
    AtomicFile file(dir / "differences.csv");
    file.write("first,second,difference,significant_05,significant_01\n");
    for (std::size_t i = 0; i < analysis.scale.size(); ++i)
      for (std::size_t j = i + 1; j < analysis.scale.size(); ++j) {
        const double difference = analysis.scale[i] - analysis.scale[j];
        file.print("{},{},{},{},{}\n", csv_field(condition_names[i]), csv_field(condition_names[j]),
                   csv_number(difference),
                   std::abs(difference) > analysis.yardstick_05 ? "yes" : "no",
                   std::abs(difference) > analysis.yardstick_01 ? "yes" : "no");
      }
    file.commit();
  }
}

std::string format_analysis_table(const PairedComparisonAnalysis& analysis,
                                  const std::vector<std::string>& names,
                                  const std::vector<FactorEffect>& factors) {
  check_names(names.size(), analysis);
  std::string out;

  std::size_t name_width = std::string_view("condition").size();
  for (const std::string& name : names) name_width = std::max(name_width, name.size());
  const std::vector<int> ranks = ranks_of(analysis.scale);
  std::vector<std::size_t> order(names.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return analysis.scale[a] > analysis.scale[b];
  });
  out += fmt::format("Scale values (grades), {} conditions rated by {} subjects\n",
                     analysis.conditions, analysis.subjects);
  out += fmt::format("  {:>4}  {:<{}}  {:>11}\n", "rank", "condition", name_width, "scale value");
  for (std::size_t i : order)
    out += fmt::format("  {:>4}  {:<{}}  {:>+11.3f}\n", ranks[i], names[i], name_width,
                       analysis.scale[i]);

  std::vector<NamedSource> lines = anova_lines(analysis, factors);
  lines[1].name = "main effect x subject";
  lines[0].name = "main effect";
  for (NamedSource& line : lines)
    if (line.name.starts_with("factor:"))
      line.name = "factor: " + line.name.substr(std::string_view("factor:").size());
  std::size_t source_width = std::string_view("source").size();
  for (const NamedSource& line : lines) source_width = std::max(source_width, line.name.size());
  out += "\nAnalysis of variance\n";
  out += fmt::format("  {:<{}}  {:>12}  {:>5}  {:>12}  {:>10}  {:>8}\n", "source", source_width,
                     "SS", "df", "MS", "F", "p");
  for (const NamedSource& line : lines) {
    const VarianceSource& s = *line.source;
    const std::string p = std::isnan(s.p) ? std::string()
                          : s.p < 1e-4    ? std::string("<0.0001")
                                          : fmt::format("{:.4f}", s.p);
    const std::string row =
        fmt::format("  {:<{}}  {:>12}  {:>5}  {:>12}  {:>10}  {:>8}  {}", line.name, source_width,
                    table_cell(s.sum_of_squares, "{:.4f}"),
                    table_cell(s.degrees_of_freedom, "{:g}"), table_cell(s.mean_square, "{:.4f}"),
                    table_cell(s.f, "{:.3f}"), p, significance_marker(s.p));
    out += row.substr(0, row.find_last_not_of(' ') + 1) + "\n";
  }
  out += "  ** p < 0.01, * p < 0.05\n";

  out += fmt::format("\nYardsticks: {}, {}  (scale values further apart differ at that level)\n",
                     yardstick_label("0.05", analysis.yardstick_05),
                     yardstick_label("0.01", analysis.yardstick_01));
  return out;
}

}  // namespace cohaptic
