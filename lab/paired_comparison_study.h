// The paired-comparison part of a lab study (the study file's `paired_comparison` block):
// every subject rates every pair of the study's conditions once, on a graded scale
// (-grades ... +grades, positive when the pair's FIRST condition felt more of the quality
// asked: finer, harder), in an order balanced across subjects; the ratings are analysed by
// Scheffe's method in Nakaya's modification (common/study/paired_comparison_analysis.h).
//
// The rater is simulated (common/study/simulated_rater.h): subject l rates a pair from the
// objective measures of the two conditions' trials of repetition (l mod repetitions) + 1,
// with its own noise (the rater's seed + l). Outputs, in the study's folder:
//   ratings.csv                 subject, position, first, second, rating, rated_by (tidy: one
//                               row per presented pair, conditions by name, in presentation order)
//   analysis/scale.csv, anova.csv, yardsticks.csv, differences.csv, table.txt
//   figures/scale.svg           the scale line with the conditions and the yardsticks
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "common/study/measures.h"
#include "common/study/simulated_rater.h"
#include "common/util/yaml_cursor.h"

namespace cohaptic {

struct PairedComparisonDesign {
  std::string question = "Which felt finer?";
  RatedQuality quality = RatedQuality::finer;
  int grades = 2;                   ///< the scale runs from -grades to +grades
  std::vector<std::string> labels;  ///< 2 grades + 1 labels, from +grades down to -grades
  int subjects = 10;                ///< at least 2
  SimulatedRaterSettings rater;
};

/// Parses a `paired_comparison` block (errors name the file, line and key).
PairedComparisonDesign parse_paired_comparison(const YamlCursor& block);

/// One pair as a subject meets it: condition indices in presentation order.
struct PresentedPair {
  int subject = 0;   ///< 0-based
  int position = 0;  ///< 0-based, in the subject's session
  int first = 0, second = 0;
};

/// Every subject's t(t-1)/2 pairs. Balanced across subjects: subject l meets the pairs in
/// the base order rotated by l P / N positions (P pairs, N subjects), so that no pair is
/// always early or late, and pair k is presented lower-index first when l + k is even, so
/// that each order is seen by half the subjects (N even; one more for N odd).
std::vector<PresentedPair> presentation_plan(int conditions, int subjects);

/// A condition's factor levels, for the factors' main effects (a full factorial).
struct StudyFactors {
  std::vector<std::string> names;        ///< the factors that vary
  std::vector<int> level_count;
  std::vector<std::vector<int>> level_of;  ///< [condition][factor]
};

/// Rates the plan with the simulated rater, writes ratings.csv, the analysis and the figure
/// into `out`, and prints the analysis table. `measures[r][c]`: condition c's measures in
/// repetition r + 1.
void run_paired_comparisons(const PairedComparisonDesign& design, const std::string& study_name,
                            const std::vector<std::string>& condition_names, const StudyFactors& factors,
                            const std::vector<std::vector<TrialMeasures>>& measures, const std::filesystem::path& out);

}  // namespace cohaptic
