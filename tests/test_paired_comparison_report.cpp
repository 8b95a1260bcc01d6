// The paired-comparison report (common/study/paired_comparison_report): the scale-line
// figure's geometry read back from the SVG (ticks at their scale values on the axis's own
// scale, yardsticks as long as they are in grades, label boxes that never overlap), the tidy
// CSV files read back against the analysis, and the terminal table.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <regex>
#include <string>
#include <vector>

#include "common/study/paired_comparison_analysis.h"
#include "common/study/paired_comparison_report.h"
#include "common/util/csv.h"
#include "common/util/error.h"
#include "common/util/not_a_number.h"
#include "support/process.h"

namespace cohaptic {
namespace {

// The published worked example of test_paired_comparison_analysis.cpp: 3 conditions, 6
// subjects; scale values -0.9444, 1.3333, -0.3889, Y(0.05) = 0.8323, Y(0.01) = 1.2617.
PairedComparisonAnalysis worked_example() {
  return analyse_paired_comparisons(
      {3, {{-2, -1, 1}, {-2, -2, 2}, {-3, 0, 3}, {-3, 0, 2}, {-1, 1, 2}, {-3, -1, 0}}});
}
const std::vector<std::string> kWorkedExampleNames = {"no delay", "20 ms delay", "80 ms delay"};

// A 2 x 2 full factorial (protocol x step), 4 subjects, made up so that some pairs differ at
// 5 % and not at 1 %.
PairedComparisonAnalysis two_by_two() {
  return analyse_paired_comparisons(
      {4, {{2, 1, 2, -1, 1, 1}, {1, 1, 2, 0, 1, 2}, {2, 0, 1, -1, 0, 1}, {1, 2, 2, 0, 1, 1}}});
}
// Names that CSV must quote.
const std::vector<std::string> kTwoByTwoNames = {"wave, 1 node", "wave, 4 nodes",
                                                 "\"plain\" 1 node", "plain 4 nodes"};
std::vector<FactorEffect> two_by_two_factors(const PairedComparisonAnalysis& a) {
  return factor_effects(a, {"protocol", "step nodes"}, {2, 2}, {{0, 0}, {0, 1}, {1, 0}, {1, 1}});
}

// The elements <tag class="css_class" ...> of an SVG document, as their attributes (and, for
// a <text>, its character data under the key "").
std::vector<std::map<std::string, std::string>> svg_elements(const std::string& svg,
                                                             const std::string& tag,
                                                             const std::string& css_class) {
  const std::regex element("<" + tag + " class=\"" + css_class + "\"([^>]*?)/?>" +
                           (tag == "text" ? "([^<]*)</text>" : ""));
  static const std::regex attribute(R"re(([a-zA-Z][a-zA-Z0-9-]*)="([^"]*)")re");
  std::vector<std::map<std::string, std::string>> found;
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), element);
       it != std::sregex_iterator(); ++it) {
    std::map<std::string, std::string>& attributes = found.emplace_back();
    const std::string inside = (*it)[1];
    for (auto a = std::sregex_iterator(inside.begin(), inside.end(), attribute);
         a != std::sregex_iterator(); ++a)
      attributes[(*a)[1]] = (*a)[2];
    if (tag == "text") attributes[""] = (*it)[2];
  }
  return found;
}

double attribute_number(const std::map<std::string, std::string>& attributes,
                        const std::string& key) {
  return std::stod(attributes.at(key));
}

// The axis as the SVG draws it: x of 0 and pixels per grade, from the tick labels.
struct AxisPixels {
  double zero = 0, per_grade = 0, left = 0, right = 0;
  double x(double grades) const { return zero + grades * per_grade; }
};

AxisPixels axis_of(const std::string& svg) {
  const auto labels = svg_elements(svg, "text", "axis-label");
  EXPECT_GE(labels.size(), 3u);
  if (labels.size() < 2) return {};
  const double first_value = std::stod(labels.front().at("")),
               last_value = std::stod(labels.back().at(""));
  const double first_x = attribute_number(labels.front(), "x"),
               last_x = attribute_number(labels.back(), "x");
  EXPECT_EQ(first_value, -last_value) << "an axis symmetric about 0";
  AxisPixels axis;
  axis.per_grade = (last_x - first_x) / (last_value - first_value);
  axis.zero = first_x - first_value * axis.per_grade;
  axis.left = first_x;
  axis.right = last_x;
  return axis;
}

constexpr double kPixel = 0.02;  // coordinates are written to 0.01 px

ScaleLineFigure worked_example_figure() {
  const PairedComparisonAnalysis a = worked_example();
  return {"Delay & \"feel\"",  "which felt finer?  positive: felt more",
          kWorkedExampleNames, a.scale,
          a.yardstick_05,      a.yardstick_01};
}

TEST(PairedComparisonReport,
     FigureTicksSitAtTheirScaleValuesAndYardsticksAreAsLongAsTheyAreInGrades) {
  const ScaleLineFigure figure = worked_example_figure();
  const std::string svg = render_scale_line_svg(figure);
  EXPECT_NE(svg.find(">Delay &amp; &quot;feel&quot;</text>"), std::string::npos) << svg;
  EXPECT_NE(svg.find(">which felt finer?  positive: felt more</text>"), std::string::npos);
  EXPECT_EQ(svg.find("nan"), std::string::npos);
  const AxisPixels axis = axis_of(svg);
  EXPECT_GT(axis.per_grade, 0);

  const auto ticks = svg_elements(svg, "line", "condition");
  const auto labels = svg_elements(svg, "text", "condition-label");
  ASSERT_EQ(ticks.size(), 3u) << svg;
  ASSERT_EQ(labels.size(), 3u);
  for (std::size_t i = 0; i < ticks.size(); ++i) {
    SCOPED_TRACE(kWorkedExampleNames[i]);
    EXPECT_EQ(labels[i].at(""), kWorkedExampleNames[i]);
    EXPECT_EQ(attribute_number(ticks[i], "x1"), attribute_number(ticks[i], "x2"))
        << "a vertical tick";
    EXPECT_NEAR(attribute_number(ticks[i], "x1"), axis.x(figure.scale[i]), kPixel);
    EXPECT_GE(attribute_number(ticks[i], "x1"), axis.left);
    EXPECT_LE(attribute_number(ticks[i], "x1"), axis.right);
  }
  // Higher scale value, further right: 20 ms (1.33) > 80 ms (-0.39) > none (-0.94).
  EXPECT_LT(attribute_number(ticks[0], "x1"), attribute_number(ticks[2], "x1"));
  EXPECT_LT(attribute_number(ticks[2], "x1"), attribute_number(ticks[1], "x1"));

  const auto yardsticks = svg_elements(svg, "line", "yardstick");
  ASSERT_EQ(yardsticks.size(), 2u);
  const double lengths[] = {figure.yardstick_05, figure.yardstick_01};
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(attribute_number(yardsticks[k], "y1"), attribute_number(yardsticks[k], "y2"))
        << "a horizontal bar";
    EXPECT_GT(attribute_number(yardsticks[k], "y1"), attribute_number(ticks[0], "y2"))
        << "below the line";
    EXPECT_NEAR(
        std::abs(attribute_number(yardsticks[k], "x2") - attribute_number(yardsticks[k], "x1")),
        std::abs(axis.x(lengths[k]) - axis.x(0)), kPixel);
    EXPECT_LE(
        std::max(attribute_number(yardsticks[k], "x1"), attribute_number(yardsticks[k], "x2")),
        axis.right + kPixel);
  }
  const auto yardstick_labels = svg_elements(svg, "text", "yardstick-label");
  ASSERT_EQ(yardstick_labels.size(), 2u);
  EXPECT_EQ(yardstick_labels[0].at(""), "Y(0.05) = 0.832");
  EXPECT_EQ(yardstick_labels[1].at(""), "Y(0.01) = 1.262");
}

// Every pair of label boxes (as the header defines them) is apart; every box is on the canvas
// and below the question.
void expect_labels_apart(const ScaleLineFigure& figure) {
  const std::string svg = render_scale_line_svg(figure);
  const auto labels = svg_elements(svg, "text", "condition-label");
  ASSERT_EQ(labels.size(), figure.names.size()) << svg;
  static const std::regex size(R"re(<svg [^>]*width="([^"]*)" height="([^"]*)")re");
  std::smatch match;
  ASSERT_TRUE(std::regex_search(svg, match, size));
  const double width = std::stod(match[1]), height = std::stod(match[2]);
  const auto question = svg_elements(svg, "text", "question");
  const double question_baseline = question.empty() ? 0 : attribute_number(question.front(), "y");
  struct Box {
    double left, right, top, bottom;
  };
  std::vector<Box> boxes;
  for (const auto& label : labels) {
    EXPECT_EQ(label.at("text-anchor"), "middle");
    const double x = attribute_number(label, "x"), y = attribute_number(label, "y"),
                 w = scale_line_label_width(label.at(""));
    boxes.push_back({x - w / 2, x + w / 2, y - kScaleLineFontSize, y + kScaleLineFontSize / 4});
    EXPECT_GE(boxes.back().left, 0) << label.at("");
    EXPECT_LE(boxes.back().right, width) << label.at("");
    EXPECT_GT(boxes.back().top, question_baseline) << label.at("");
    EXPECT_LT(boxes.back().bottom, height) << label.at("");
  }
  for (std::size_t i = 0; i < boxes.size(); ++i)
    for (std::size_t j = i + 1; j < boxes.size(); ++j) {
      const bool apart = boxes[i].right <= boxes[j].left || boxes[j].right <= boxes[i].left ||
                         boxes[i].bottom <= boxes[j].top || boxes[j].bottom <= boxes[i].top;
      EXPECT_TRUE(apart) << labels[i].at("") << " overlaps " << labels[j].at("") << "\n" << svg;
    }
  // Nothing drawn below the document's bottom (it grows for many rows).
  static const std::regex y_coordinate(R"re(\by[12]?="([^"]*)")re");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), y_coordinate);
       it != std::sregex_iterator(); ++it)
    EXPECT_LT(std::stod((*it)[1]), height);
}

TEST(PairedComparisonReport, FigureLabelsNeverOverlap) {
  ScaleLineFigure figure;
  figure.question = "which felt harder?";
  figure.yardstick_05 = 0.8;
  figure.yardstick_01 = 1.2;

  // Two conditions 0.01 apart: their labels go on different rows.
  figure.names = {"slow", "slower"};
  figure.scale = {0.30, 0.31};
  expect_labels_apart(figure);
  const auto two = svg_elements(render_scale_line_svg(figure), "text", "condition-label");
  ASSERT_EQ(two.size(), 2u);
  EXPECT_NE(two[0].at("y"), two[1].at("y"));

  // Well apart: one row, no needless staggering.
  figure.names = {"soft", "medium", "hard"};
  figure.scale = {-1, 0, 1};
  expect_labels_apart(figure);
  const auto spread = svg_elements(render_scale_line_svg(figure), "text", "condition-label");
  ASSERT_EQ(spread.size(), 3u);
  EXPECT_EQ(spread[0].at("y"), spread[1].at("y"));
  EXPECT_EQ(spread[1].at("y"), spread[2].at("y"));

  // A crowd: twelve labels of different lengths within 0.05 of each other, some at the same
  // value, next to the axis's ends, in a figure too short for them.
  figure.names.clear();
  figure.scale.clear();
  for (int i = 0; i < 12; ++i) {
    figure.names.push_back(
        std::string(static_cast<std::size_t>(3 + (i * 7) % 11), static_cast<char>('a' + i)));
    figure.scale.push_back(0.004 * (i / 2));
  }
  figure.names.push_back("a name long enough to stick out at the left end of the axis");
  figure.scale.push_back(-1.9);
  figure.names.push_back("a name long enough to stick out at the right end of the axis");
  figure.scale.push_back(1.9);
  figure.height = 120;
  expect_labels_apart(figure);
}

TEST(PairedComparisonReport, FigureRefusesWhatItCannotDraw) {
  const ScaleLineFigure good = worked_example_figure();
  EXPECT_NO_THROW(render_scale_line_svg(good));
  ScaleLineFigure bad = good;
  bad.names.pop_back();
  EXPECT_THROW(render_scale_line_svg(bad), Error) << "a name missing";
  bad = good;
  bad.scale[1] = kNaN;
  EXPECT_THROW(render_scale_line_svg(bad), Error) << "a scale value NaN";
  bad = good;
  bad.scale[0] = -std::numeric_limits<double>::infinity();
  EXPECT_THROW(render_scale_line_svg(bad), Error) << "a scale value infinite";
  bad = good;
  bad.yardstick_01 = kNaN;
  EXPECT_THROW(render_scale_line_svg(bad), Error) << "a yardstick NaN";
  bad = good;
  bad.yardstick_05 = -0.5;
  EXPECT_THROW(render_scale_line_svg(bad), Error) << "a negative yardstick";
  bad = good;
  bad.width = 0;
  EXPECT_THROW(render_scale_line_svg(bad), Error) << "no width";
  bad = good;
  bad.height = -260;
  EXPECT_THROW(render_scale_line_svg(bad), Error) << "negative height";
  bad = good;
  bad.width = kNaN;
  EXPECT_THROW(render_scale_line_svg(bad), Error) << "width NaN";

  const std::filesystem::path dir = testing::scratch_directory("scale-line-svg");
  write_scale_line_svg(dir / "scale.svg", good);
  std::ifstream in(dir / "scale.svg");
  const std::string written((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(written, render_scale_line_svg(good));
  EXPECT_THROW(write_scale_line_svg(dir / "missing" / "scale.svg", good), Error);
}

// A file's lines split into fields, the header first.
std::vector<std::vector<std::string>> read_csv_rows(const std::filesystem::path& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in) << path;
  std::vector<std::vector<std::string>> rows;
  for (std::string line; std::getline(in, line);) rows.push_back(split_csv_line(line));
  return rows;
}

// {:.9g} keeps nine significant digits: at most half a unit of the ninth apart.
void expect_number(const std::string& field, double value, const std::string& what) {
  if (std::isnan(value)) {
    EXPECT_EQ(field, "") << what;
    return;
  }
  ASSERT_FALSE(field.empty()) << what;
  EXPECT_NEAR(std::stod(field), value, 5e-9 * std::abs(value) + 1e-300) << what;
}

TEST(PairedComparisonReport, CsvFilesReadBackAsTheAnalysis) {
  const std::filesystem::path root = testing::scratch_directory("paired-comparison-csv");
  int yes = 0, no = 0;
  for (const bool factorial : {false, true}) {
    SCOPED_TRACE(factorial ? "2 x 2 factorial" : "worked example");
    const PairedComparisonAnalysis a = factorial ? two_by_two() : worked_example();
    const std::vector<std::string>& names = factorial ? kTwoByTwoNames : kWorkedExampleNames;
    const std::vector<FactorEffect> factors =
        factorial ? two_by_two_factors(a) : std::vector<FactorEffect>{};
    const std::filesystem::path dir =
        root / (factorial ? "factorial" : "worked") / "tables";  // made by the writer
    write_analysis_csv(dir, a, names, factors);
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir),
                            std::filesystem::directory_iterator()),
              4)
        << "four files and no temporary left";

    const auto scale = read_csv_rows(dir / "scale.csv");
    ASSERT_EQ(scale.size(), names.size() + 1);
    EXPECT_EQ(scale[0], (std::vector<std::string>{"condition", "scale_value", "rank"}));
    for (std::size_t i = 0; i < names.size(); ++i) {
      const auto& row = scale[i + 1];
      ASSERT_EQ(row.size(), 3u);
      EXPECT_EQ(row[0], names[i]);
      expect_number(row[1], a.scale[i], names[i]);
      EXPECT_EQ(std::stoi(row[2]), 1 + std::count_if(a.scale.begin(), a.scale.end(),
                                                     [&](double s) { return s > a.scale[i]; }));
    }
    if (!factorial) {
      EXPECT_EQ((std::vector<std::string>{scale[1][2], scale[2][2], scale[3][2]}),
                (std::vector<std::string>{"3", "1", "2"}));
    }

    const auto anova = read_csv_rows(dir / "anova.csv");
    EXPECT_EQ(anova[0], (std::vector<std::string>{"source", "sum_of_squares", "degrees_of_freedom",
                                                  "mean_square", "f", "p"}));
    std::vector<std::pair<std::string, VarianceSource>> expected{
        {"main_effect", a.main_effect},
        {"main_effect_x_subject", a.main_by_subject},
        {"combination", a.combination},
        {"error", a.error},
        {"total", a.total}};
    for (const FactorEffect& factor : factors)
      expected.emplace_back("factor:" + factor.name, factor.source);
    ASSERT_EQ(anova.size(), expected.size() + 1);
    for (std::size_t k = 0; k < expected.size(); ++k) {
      const auto& row = anova[k + 1];
      const auto& [name, source] = expected[k];
      ASSERT_EQ(row.size(), 6u);
      EXPECT_EQ(row[0], name);
      expect_number(row[1], source.sum_of_squares, name);
      expect_number(row[2], source.degrees_of_freedom, name);
      expect_number(row[3], source.mean_square, name);
      expect_number(row[4], source.f, name + " F");
      expect_number(row[5], source.p, name + " p");
    }
    EXPECT_EQ(anova[4][4], "") << "the error has no F";
    EXPECT_EQ(anova[5][5], "") << "the total has no p";
    if (factorial) {
      EXPECT_EQ(anova.back()[0], "factor:interaction");
    }

    const auto yardsticks = read_csv_rows(dir / "yardsticks.csv");
    ASSERT_EQ(yardsticks.size(), 3u);
    EXPECT_EQ(yardsticks[0], (std::vector<std::string>{"level", "yardstick"}));
    EXPECT_EQ(yardsticks[1][0], "0.05");
    expect_number(yardsticks[1][1], a.yardstick_05, "Y(0.05)");
    EXPECT_EQ(yardsticks[2][0], "0.01");
    expect_number(yardsticks[2][1], a.yardstick_01, "Y(0.01)");

    const auto differences = read_csv_rows(dir / "differences.csv");
    EXPECT_EQ(differences[0], (std::vector<std::string>{"first", "second", "difference",
                                                        "significant_05", "significant_01"}));
    ASSERT_EQ(differences.size(), static_cast<std::size_t>(pair_count(a.conditions)) + 1);
    std::size_t row_index = 1;
    for (std::size_t i = 0; i < names.size(); ++i)
      for (std::size_t j = i + 1; j < names.size(); ++j) {
        const auto& row = differences[row_index++];
        ASSERT_EQ(row.size(), 5u);
        EXPECT_EQ(row[0], names[i]);
        EXPECT_EQ(row[1], names[j]);
        const double difference = a.scale[i] - a.scale[j];
        expect_number(row[2], difference, row[0] + " - " + row[1]);
        EXPECT_EQ(row[3], std::abs(difference) > a.yardstick_05 ? "yes" : "no")
            << row[0] << " - " << row[1];
        EXPECT_EQ(row[4], std::abs(difference) > a.yardstick_01 ? "yes" : "no")
            << row[0] << " - " << row[1];
        yes += (row[3] == "yes") + (row[4] == "yes");
        no += (row[3] == "no") + (row[4] == "no");
      }
  }
  EXPECT_GT(yes, 0) << "the data should hold differences on both sides of the yardsticks";
  EXPECT_GT(no, 0);
}

TEST(PairedComparisonReport, CsvWriterRefusesWhatItCannotWrite) {
  const std::filesystem::path dir = testing::scratch_directory("paired-comparison-csv-refused");
  const PairedComparisonAnalysis a = worked_example();
  EXPECT_THROW(write_analysis_csv(dir / "tables", a, {"only", "two"}, {}), Error)
      << "a name missing";
  EXPECT_THROW(write_analysis_csv(dir / "tables", a, {"one", "two", "three", "four"}, {}), Error)
      << "a name too many";
  EXPECT_FALSE(std::filesystem::exists(dir / "tables" / "scale.csv"));
  std::ofstream(dir / "a file") << "not a directory\n";
  EXPECT_THROW(write_analysis_csv(dir / "a file", a, kWorkedExampleNames, {}), Error);
  EXPECT_THROW(write_analysis_csv(dir / "a file" / "below", a, kWorkedExampleNames, {}), Error);
}

// The line of `text` that starts (after its indent) with `start`, or "".
std::string line_starting(const std::string& text, const std::string& start) {
  for (std::size_t begin = 0; begin < text.size();) {
    const std::size_t end = std::min(text.find('\n', begin), text.size());
    const std::string line = text.substr(begin, end - begin);
    if (line.find_first_not_of(' ') != std::string::npos &&
        line.substr(line.find_first_not_of(' ')).starts_with(start))
      return line;
    begin = end + 1;
  }
  return "";
}

TEST(PairedComparisonReport, TextTableListsConditionsHighToLowTheAnovaAndTheYardsticks) {
  const PairedComparisonAnalysis a = worked_example();
  const std::vector<FactorEffect> delay = factor_effects(a, {"delay"}, {3}, {{0}, {1}, {2}});
  const std::string table = format_analysis_table(a, kWorkedExampleNames, delay);
  for (const std::string& name : kWorkedExampleNames)
    EXPECT_NE(table.find(name), std::string::npos) << name << "\n" << table;
  // 20 ms (1.333) above 80 ms (-0.389) above none (-0.944).
  EXPECT_LT(table.find("20 ms delay"), table.find("80 ms delay")) << table;
  EXPECT_LT(table.find("80 ms delay"), table.find("no delay")) << table;
  EXPECT_NE(line_starting(table, "1  20 ms delay").find("+1.333"), std::string::npos) << table;
  EXPECT_NE(table.find("Y(0.05) = 0.832"), std::string::npos) << table;
  EXPECT_NE(table.find("Y(0.01) = 1.262"), std::string::npos) << table;

  // Main effect p = 0.0007: **; main effect x subject p = 0.247 and combination p = 0.771: none.
  const std::string main_line = line_starting(table, "main effect ");
  EXPECT_TRUE(main_line.ends_with(" **")) << table;
  EXPECT_NE(main_line.find("43.113"), std::string::npos) << main_line;
  EXPECT_NE(main_line.find("0.0007"), std::string::npos) << main_line;
  EXPECT_EQ(line_starting(table, "main effect x subject").find('*'), std::string::npos) << table;
  EXPECT_EQ(line_starting(table, "combination").find('*'), std::string::npos) << table;
  EXPECT_EQ(line_starting(table, "error").find('*'), std::string::npos) << table;
  EXPECT_TRUE(line_starting(table, "factor: delay").ends_with(" **")) << table;

  // p between 0.01 and 0.05: one star.
  PairedComparisonAnalysis one_star = a;
  one_star.combination.p = 0.03;
  EXPECT_TRUE(line_starting(format_analysis_table(one_star, kWorkedExampleNames, {}), "combination")
                  .ends_with(" 0.0300  *"))
      << format_analysis_table(one_star, kWorkedExampleNames, {});

  EXPECT_THROW(format_analysis_table(a, {"one"}, {}), Error);
}

}  // namespace
}  // namespace cohaptic
