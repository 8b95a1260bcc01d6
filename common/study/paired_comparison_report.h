// What a paired-comparison analysis (paired_comparison_analysis.h) hands to a reader: the
// scale-line figure drawn for Scheffe's method, tidy CSV tables, and a plain-text table for
// the terminal.
//
// The figure: one horizontal scale line in grades (round ticks symmetric about 0, wide enough
// for every scale value and for the longer yardstick), each condition a tick on the line at its
// scale value with its name above, and below the line the yardsticks Y(0.05) and Y(0.01) as
// bars drawn from the axis's left end at the axis's own scale, labelled to their left. Plain
// SVG 1.1 in the style of svg_plot.h, every text XML-escaped.
//
// Invariants the tests rely on: each condition is exactly one <line class="condition">
// (vertical, at x(scale value)) and one <text class="condition-label"> (text-anchor middle);
// each yardstick is exactly one <line class="yardstick"> (horizontal, length |x(Y) - x(0)|).
// A label is taken to cover scale_line_label_width(name) pixels centred on its x and
// [y - kScaleLineFontSize, y + kScaleLineFontSize / 4] vertically (y its baseline); labels
// that would overlap, with kScaleLineLabelGap to spare, go on rows further above the line, so
// no two boxes overlap. The document is `height` tall, or taller when the rows need it.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "common/study/paired_comparison_analysis.h"

namespace cohaptic {

struct ScaleLineFigure {
  std::string title;
  std::string question;                       ///< e.g. "which felt finer?  positive: felt more"
  std::vector<std::string> names;             ///< one per condition
  std::vector<double> scale;                  ///< alpha_i per condition, in grades
  double yardstick_05 = 0, yardstick_01 = 0;  ///< in grades, not negative
  double width = 800, height = 260;           ///< SVG user units (pixels)
};

/// The pixel sizes the figure assumes for a label's box (12 px sans-serif text).
inline constexpr double kScaleLineFontSize = 12;
inline constexpr double kScaleLineCharWidth = 7;
inline constexpr double kScaleLineLabelGap =
    6;  ///< least horizontal space between two labels on a row

/// The width the figure reserves for `text` (kScaleLineCharWidth per UTF-8 character).
double scale_line_label_width(std::string_view text);

/// The SVG document. Throws Error when names and scale differ in length, a scale value or a
/// yardstick is not finite or a yardstick is negative, or width or height is not positive.
std::string render_scale_line_svg(const ScaleLineFigure& figure);

/// render_scale_line_svg() written atomically to `path` (AtomicFile). Throws Error.
void write_scale_line_svg(const std::filesystem::path& path, const ScaleLineFigure& figure);

/// Writes into `dir` (made if missing), each file atomically (AtomicFile), numbers as {:.9g},
/// NaN as an empty field:
///   scale.csv        condition,scale_value,rank       conditions in their order; rank 1 = the
///                                                     highest, equal values share the better rank
///   anova.csv        source,sum_of_squares,degrees_of_freedom,mean_square,f,p
///                    main_effect, main_effect_x_subject, combination, error, total, then
///                    factor:<name> per entry of `factors` (in their order)
///   yardsticks.csv   level,yardstick                  0.05 then 0.01
///   differences.csv  first,second,difference,significant_05,significant_01
///                    every pair i < j, difference = alpha_i - alpha_j, "yes" when
///                    |difference| > Y at that level, else "no"
/// Throws Error when the names are not one per condition or a file cannot be written.
void write_analysis_csv(const std::filesystem::path& dir, const PairedComparisonAnalysis& analysis,
                        const std::vector<std::string>& condition_names,
                        const std::vector<FactorEffect>& factors);

/// A plain-text report for the terminal: scale values from highest to lowest, the analysis of
/// variance (with the factors' lines) marked ** for p < 0.01 and * for p < 0.05, and the
/// yardsticks as "Y(0.05) = 0.832". Throws Error when the names are not one per condition.
std::string format_analysis_table(const PairedComparisonAnalysis& analysis,
                                  const std::vector<std::string>& names,
                                  const std::vector<FactorEffect>& factors);

}  // namespace cohaptic
