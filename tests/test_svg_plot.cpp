// The SVG plotter (common/study/svg_plot): well-formed XML with one element per series or bar,
// finite coordinates, escaped text, round ticks, and no crash on NaN, empty or constant data.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "common/study/svg_plot.h"
#include "common/util/error.h"
#include "common/util/not_a_number.h"
#include "support/process.h"

namespace cohaptic {
namespace {

// Checks that tags balance, with exactly one root <svg>, and that character data has no raw '<'
// and every '&' starts an entity; returns "" or what is wrong.
std::string xml_problem(const std::string& xml) {
  std::vector<std::string> open;
  int roots = 0;
  std::size_t i = 0;
  const auto check_text = [](std::string_view text) -> std::string {
    for (std::size_t j = 0; j < text.size(); ++j)
      if (text[j] == '&') {
        const std::size_t semi = text.find(';', j);
        if (semi == std::string::npos || semi - j > 6) return "bare & in text";
      }
    return "";
  };
  while (i < xml.size()) {
    const std::size_t lt = xml.find('<', i);
    if (const std::string p = check_text(std::string_view(xml).substr(i, lt - i)); !p.empty())
      return p;
    if (lt == std::string::npos) break;
    if (xml.compare(lt, 2, "<?") == 0) {
      i = xml.find("?>", lt);
      if (i == std::string::npos) return "unclosed <?";
      i += 2;
      continue;
    }
    const std::size_t gt = xml.find('>', lt);
    if (gt == std::string::npos) return "unclosed tag";
    const std::string tag = xml.substr(lt + 1, gt - lt - 1);
    if (tag.find('<') != std::string::npos) return "< inside a tag";
    // Attribute values are quoted and escaped: an even number of quotes.
    if (std::count(tag.begin(), tag.end(), '"') % 2 != 0) return "odd quotes in <" + tag + ">";
    if (tag.starts_with("/")) {
      if (open.empty() || open.back() != tag.substr(1))
        return "unbalanced </" + tag.substr(1) + ">";
      open.pop_back();
    } else {
      const std::string name = tag.substr(0, tag.find_first_of(" /"));
      if (open.empty()) {
        if (name != "svg") return "root is <" + name + ">";
        ++roots;
      }
      if (!tag.ends_with("/")) open.push_back(name);
    }
    i = gt + 1;
  }
  if (!open.empty()) return "unclosed <" + open.back() + ">";
  if (roots != 1) return "not exactly one root";
  return "";
}

int count(const std::string& text, const std::string& what) {
  int n = 0;
  for (std::size_t i = text.find(what); i != std::string::npos; i = text.find(what, i + 1)) ++n;
  return n;
}

// Every number in a coordinate attribute parses and is finite; returns how many there were.
int check_coordinates(const std::string& svg) {
  static const std::regex attribute(
      R"re(\b(x|y|x1|y1|x2|y2|cx|cy|width|height|points)="([^"]*)")re");
  int numbers = 0;
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), attribute);
       it != std::sregex_iterator(); ++it) {
    std::string value = (*it)[2];
    for (char& ch : value)
      if (ch == ',') ch = ' ';
    std::istringstream in(value);
    std::string token;
    while (in >> token) {
      char* end = nullptr;
      const double v = std::strtod(token.c_str(), &end);
      EXPECT_EQ(*end, '\0') << token;
      EXPECT_TRUE(std::isfinite(v)) << token;
      ++numbers;
    }
  }
  return numbers;
}

LinePlot three_series() {
  LinePlot plot;
  plot.title = "Reaction force, T300 P0";
  plot.x_label = "time [s]";
  plot.y_label = "force / peak";
  for (int s = 0; s < 3; ++s) {
    Series series;
    series.label = "series " + std::to_string(s);
    for (int i = 0; i <= 100; ++i) {
      series.x.push_back(0.01 * i);
      series.y.push_back(std::sin(0.03 * i + s));
    }
    plot.series.push_back(series);
  }
  return plot;
}

TEST(SvgPlot, LinePlotIsBalancedXmlWithOnePolylinePerSeries) {
  const std::string svg = render_svg(three_series());
  EXPECT_EQ(xml_problem(svg), "") << svg;
  EXPECT_EQ(count(svg, "<polyline"), 3);
  EXPECT_EQ(count(svg, "<path"), 0);
  EXPECT_EQ(count(svg, "<rect"), 0);
  EXPECT_EQ(count(svg, "series 2</text>"), 1);  // legend
  EXPECT_EQ(count(svg, ">Reaction force, T300 P0</text>"), 1);
  EXPECT_GT(check_coordinates(svg), 303 * 2);
  EXPECT_EQ(svg.find("nan"), std::string::npos);
  EXPECT_EQ(svg.find("inf"), std::string::npos);
}

TEST(SvgPlot, BarChartHasOneRectPerFiniteBarAndErrorBars) {
  BarChart chart;
  chart.title = "Roughness";
  chart.y_label = "roughness";
  chart.bars = {{"T0", 0.01, 0.002, ""},
                {"T150", 0.05, 0.01, "#ff0000"},
                {"T300", -0.02, 0.005, ""},
                {"none", kNaN, kNaN, ""},
                {"no sd", 0.03, kNaN, ""}};
  const std::string svg = render_svg(chart);
  EXPECT_EQ(xml_problem(svg), "") << svg;
  EXPECT_EQ(count(svg, "<rect class=\"bar\""), 4);
  EXPECT_EQ(count(svg, "<rect"), 4);
  EXPECT_EQ(count(svg, "<polyline"), 0);
  EXPECT_EQ(count(svg, ">none</text>"), 1);              // the category is still labelled
  EXPECT_EQ(count(svg, "stroke-width=\"1.5\""), 3 * 3);  // three error bars of three lines each
  EXPECT_EQ(count(svg, "fill=\"#ff0000\""), 1);
  check_coordinates(svg);
  EXPECT_EQ(svg.find("nan"), std::string::npos);

  // Heights are proportional to the means, measured from the zero line.
  static const std::regex rect(
      R"re(<rect class="bar" x="[^"]*" y="([^"]*)" width="[^"]*" height="([^"]*)")re");
  std::vector<double> heights;
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), rect); it != std::sregex_iterator();
       ++it)
    heights.push_back(std::stod((*it)[2]));
  ASSERT_EQ(heights.size(), 4u);
  EXPECT_NEAR(heights[1] / heights[0], 5, 0.01);
  EXPECT_NEAR(heights[2] / heights[0], 2, 0.01);
}

TEST(SvgPlot, TextAndColoursAreEscaped) {
  EXPECT_EQ(xml_escape("a < b & c > \"d\" 'e'\x01"),
            "a &lt; b &amp; c &gt; &quot;d&quot; &apos;e&apos;");
  LinePlot plot = three_series();
  plot.title = "F < 5 N & \"x\" > 0";
  plot.series[0].label = "<script>alert(1)</script>";
  plot.series[1].colour = "red\" onload=\"x";
  const std::string svg = render_svg(plot);
  EXPECT_EQ(xml_problem(svg), "") << svg;
  EXPECT_NE(svg.find("F &lt; 5 N &amp; &quot;x&quot; &gt; 0"), std::string::npos);
  EXPECT_NE(svg.find("&lt;script&gt;alert(1)&lt;/script&gt;"), std::string::npos);
  EXPECT_EQ(svg.find("<script"), std::string::npos);
  EXPECT_EQ(svg.find("onload=\""), std::string::npos);
}

TEST(SvgPlot, NanEmptyConstantAndSinglePointSeriesDoNotCrash) {
  LinePlot plot;
  plot.title = "edge cases";
  plot.series.push_back({"empty", {}, {}, "", false});
  plot.series.push_back({"all NaN", {kNaN, kNaN}, {1, kNaN}, "", false});
  plot.series.push_back({"constant", {0, 1, 2, 3}, {2, 2, 2, 2}, "", false});
  plot.series.push_back({"with gaps",
                         {0, kNaN, 2, 3, std::numeric_limits<double>::infinity()},
                         {1, 5, kNaN, 3, 4},
                         "",
                         true});
  plot.series.push_back({"single", {1.5}, {2.5}, "", false});
  plot.series.push_back({"uneven", {0, 1, 2}, {1, 2}, "", false});
  const std::string svg = render_svg(plot);
  EXPECT_EQ(xml_problem(svg), "") << svg;
  EXPECT_EQ(count(svg, "<polyline"), 4);    // not "empty" nor "all NaN"
  EXPECT_EQ(count(svg, "<circle"), 2 + 1);  // markers of "with gaps" (2 finite points) + "single"
  check_coordinates(svg);
  EXPECT_EQ(svg.find("nan"), std::string::npos);

  // Nothing finite at all, one constant value, and nothing at all.
  for (const LinePlot& p : {LinePlot{"", "", "", {{"x", {kNaN}, {kNaN}, "", false}}},
                            LinePlot{"", "", "", {{"c", {1, 1}, {0, 0}, "", false}}}, LinePlot{}}) {
    const std::string s = render_svg(p);
    EXPECT_EQ(xml_problem(s), "") << s;
    check_coordinates(s);
  }
  const std::string empty_bars = render_svg(BarChart{});
  EXPECT_EQ(xml_problem(empty_bars), "");
  EXPECT_EQ(count(empty_bars, "<rect"), 0);
  LinePlot bad;
  bad.width = 0;
  EXPECT_THROW(render_svg(bad), Error);
}

TEST(SvgPlot, TicksAreRoundNumbersCoveringTheRange) {
  const struct {
    double lo, hi;
  } cases[] = {{0, 1},        {0.013, 0.87}, {-3.7, 12.2}, {1000, 1003},
               {-1e-6, 2e-6}, {42, 4200},    {0.1, 0.3}};
  for (const auto& c : cases) {
    const std::vector<double> ticks = nice_ticks(c.lo, c.hi);
    ASSERT_GE(ticks.size(), 3u) << c.lo << " " << c.hi;
    EXPECT_LE(ticks.size(), 12u);
    EXPECT_LE(ticks.front(), c.lo);
    EXPECT_GE(ticks.back(), c.hi);
    const double step = ticks[1] - ticks[0];
    const double mantissa = step / std::pow(10.0, std::floor(std::log10(step) + 1e-9));
    EXPECT_TRUE(std::abs(mantissa - 1) < 1e-6 || std::abs(mantissa - 2) < 1e-6 ||
                std::abs(mantissa - 5) < 1e-6)
        << step;
    for (double t : ticks) EXPECT_NEAR(t / step, std::round(t / step), 1e-6) << t;
  }
  EXPECT_EQ(nice_ticks(1, 1).size(), 2u);  // degenerate: returned as given
  // Tick labels in the picture are short and round.
  LinePlot plot;
  plot.series.push_back({"", {0.1, 0.3}, {0.1, 0.3}, "", false});
  const std::string svg = render_svg(plot);
  EXPECT_NE(svg.find(">0.25</text>"), std::string::npos) << svg;
  EXPECT_EQ(svg.find("0.30000000"), std::string::npos);
}

TEST(SvgPlot, WriteSvgWritesTheWholeFile) {
  const std::filesystem::path dir = testing::scratch_directory("svg");
  const LinePlot plot = three_series();
  write_svg(dir / "plot.svg", plot);
  std::ifstream in(dir / "plot.svg");
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), render_svg(plot));
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir),
                          std::filesystem::directory_iterator()),
            1);
  EXPECT_THROW(write_svg(dir / "missing" / "plot.svg", plot), Error);
}

}  // namespace
}  // namespace cohaptic
