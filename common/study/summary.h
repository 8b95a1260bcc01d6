// Summary of trials per condition: for each condition key (e.g. "S30-T150-P1") and each
// measure of TrialMeasures, the mean, the sample standard deviation and the number of trials
// that had a value. This is what summary.csv holds (columns condition, measure, mean, sd, n).
//
// Definitions, over the finite values v_1..v_n of one measure in one condition (NaN and
// infinite values are measures that had nothing to measure and are left out, so n may differ
// between measures of the same condition):
//   mean = (1/n) sum v_i                        (NaN if n = 0)
//   sd   = sqrt(sum (v_i - mean)^2 / (n - 1))   (sample sd; NaN if n < 2)
// Order: conditions in order of first appearance among the trials, and within a condition the
// measures in order of first appearance among the trials' values (for condition_trial():
// named_measures() order, measures.h); every (condition, measure) pair appears, even with
// n = 0.
#pragma once

#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "common/study/measures.h"

namespace cohaptic {

struct Statistics {
  double mean = 0;
  double sd = 0;
  std::size_t n = 0;
};

/// mean, sd, n of the finite values, as defined above.
Statistics describe(std::span<const double> values);

/// One named value of a trial: a measure, or another per-trial number (e.g. a rate).
struct TrialValue {
  std::string name;
  double value = 0;
};

/// One trial and the condition it was run in.
struct ConditionTrial {
  std::string condition;
  std::vector<TrialValue> values;
};

/// A trial's measures, in the order of named_measures().
ConditionTrial condition_trial(std::string condition, const TrialMeasures& measures);

struct ConditionSummary {
  std::string condition;
  std::string measure;  ///< a TrialValue name
  double mean = 0;
  double sd = 0;
  std::size_t n = 0;
};

std::vector<ConditionSummary> summarize(const std::vector<ConditionTrial>& trials);

/// The summary as CSV with header "condition,measure,mean,sd,n", written atomically; numbers
/// with 9 significant digits, NaN as "nan"; a condition containing , " or a line break is quoted.
/// Throws Error if the file cannot be written.
void write_summary_csv(const std::filesystem::path& path,
                       const std::vector<ConditionSummary>& summary);

}  // namespace cohaptic
