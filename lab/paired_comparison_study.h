// The paired-comparison part of a lab study (the study file's `paired_comparison` block):
// every subject rates every pair of the study's conditions once, on a graded scale
// (-grades ... +grades, positive when the pair's FIRST condition felt more of the quality
// asked: finer, harder), in an order balanced across subjects; the ratings are analysed by
// Scheffe's method in Nakaya's modification (common/study/paired_comparison_analysis.h).
//
// The rater is simulated (common/study/simulated_rater.h: subject l rates a pair from the
// objective measures of the two conditions' trials of repetition (l mod repetitions) + 1,
// with its own noise, the rater's seed + l) or a person (lab/person_pairs.h: one subject
// at a time switches between the pair's two conditions in one session and rates them).
// Outputs, in the study's folder:
//   pair_plan.csv               subject, position, first, second: each subject's order
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

enum class RaterKind { simulated, person };

struct PairedComparisonDesign {
  std::string question = "Which felt finer?";
  RatedQuality quality = RatedQuality::finer;
  int grades = 2;                   ///< the scale runs from -grades to +grades
  std::vector<std::string> labels;  ///< 2 grades + 1 labels, from +grades down to -grades
  int subjects = 10;                ///< at least 2
  RaterKind rater_kind = RaterKind::simulated;
  SimulatedRaterSettings rater;  ///< the simulated rater's
  // A person's session (lab/person_pairs.h):
  int practice_pairs = 1;                ///< pairs felt before the rated ones, not rated
  std::string show_object = "practice";  ///< the live view served: practice, always or never
  double pair_duration_s = 60;  ///< the longest a pair is felt (then it is rated, not switched)
  int switch_button = -1;       ///< a device button that switches too (person rater); -1: none
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
  std::vector<std::string> names;  ///< the factors that vary
  std::vector<int> level_count;
  std::vector<std::vector<int>> level_of;  ///< [condition][factor]
};

/// Writes `file` (pair_plan.csv: subject, position, first, second; 1-based) from
/// presentation_plan(): the order each subject meets the pairs in, as run.
void write_pair_plan(const std::filesystem::path& file,
                     const std::vector<std::string>& condition_names, int subjects);

/// One row of ratings.csv: a pair as presented, and its rating (positive: the first felt more).
struct PairRatingRow {
  int subject = 0, position = 0;  ///< 1-based
  std::string first, second;      ///< the conditions' names, in presentation order
  int rating = 0;
  std::string rated_by;  ///< "simulated" or "person"
};

/// ratings.csv's rows (none if the file does not exist); throws Error naming the file and
/// line of a malformed row.
std::vector<PairRatingRow> read_ratings(const std::filesystem::path& file);
/// Writes ratings.csv atomically.
void write_ratings(const std::filesystem::path& file, const std::vector<PairRatingRow>& rows);

/// The simulated rater's ratings of the whole plan. `measures[r][c]`: condition c's
/// measures in repetition r + 1.
std::vector<PairRatingRow> simulated_ratings(
    const PairedComparisonDesign& design, const std::vector<std::string>& condition_names,
    const std::vector<std::vector<TrialMeasures>>& measures);

/// Scheffe's analysis of `rows` (every subject's every pair, each once: else Error naming
/// what is missing) into `out`/analysis and `out`/figures/scale.svg; prints the table.
void analyse_ratings(const PairedComparisonDesign& design, const std::string& study_name,
                     const std::vector<std::string>& condition_names, const StudyFactors& factors,
                     const std::vector<PairRatingRow>& rows, const std::filesystem::path& out);

}  // namespace cohaptic
