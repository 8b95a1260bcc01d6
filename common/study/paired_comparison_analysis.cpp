#include "common/study/paired_comparison_analysis.h"

#include <fmt/format.h>

#include <boost/math/distributions/fisher_f.hpp>
#include <cmath>
#include <limits>
#include <set>

#include "common/study/studentized_range.h"
#include "common/util/error.h"

namespace cohaptic {

namespace {

constexpr double kNoValue = std::numeric_limits<double>::quiet_NaN();

// The line for a source tested against the error's mean square.
VarianceSource tested(double sum_of_squares, double degrees_of_freedom,
                      const VarianceSource& error) {
  VarianceSource source{sum_of_squares, degrees_of_freedom, sum_of_squares / degrees_of_freedom,
                        kNoValue, kNoValue};
  if (error.mean_square > 0) {
    source.f = source.mean_square / error.mean_square;
    const boost::math::fisher_f_distribution<double> f_distribution(degrees_of_freedom,
                                                                    error.degrees_of_freedom);
    source.p = boost::math::cdf(boost::math::complement(f_distribution, std::max(0.0, source.f)));
  } else if (source.mean_square > 0) {  // no error at all: any effect is certain
    source.f = std::numeric_limits<double>::infinity();
    source.p = 0;
  }
  return source;
}

VarianceSource untested(double sum_of_squares, double degrees_of_freedom) {
  return {sum_of_squares, degrees_of_freedom, sum_of_squares / degrees_of_freedom, kNoValue,
          kNoValue};
}

void check(const PairedComparisonRatings& ratings) {
  const int t = ratings.conditions;
  if (t < 3)
    throw Error(
        fmt::format("paired comparisons: {} conditions; Scheffe's analysis needs at least 3", t));
  if (ratings.ratings.size() < 2)
    throw Error(fmt::format("paired comparisons: {} subjects; the analysis needs at least 2",
                            ratings.ratings.size()));
  for (std::size_t l = 0; l < ratings.ratings.size(); ++l) {
    const auto& subject = ratings.ratings[l];
    if (static_cast<int>(subject.size()) != pair_count(t))
      throw Error(
          fmt::format("paired comparisons: subject {} has {} ratings; {} conditions make {} pairs",
                      l + 1, subject.size(), t, pair_count(t)));
    for (std::size_t pair = 0; pair < subject.size(); ++pair)
      if (!std::isfinite(subject[pair]))
        throw Error(fmt::format(
            "paired comparisons: subject {}'s rating of pair {} is not a number", l + 1, pair + 1));
  }
}

}  // namespace

int pair_count(int conditions) { return conditions * (conditions - 1) / 2; }

int pair_index(int first, int second, int conditions) {
  // The pairs before row `first`: (t-1) + (t-2) + ... + (t-first).
  return first * (2 * conditions - first - 1) / 2 + (second - first - 1);
}

PairedComparisonAnalysis analyse_paired_comparisons(const PairedComparisonRatings& ratings) {
  check(ratings);
  const int t = ratings.conditions;
  const int n = static_cast<int>(ratings.ratings.size());
  // X_i.l = sum over j of x_ijl; X_ij. = sum over l of x_ijl (i < j); S_T = sum of squares.
  std::vector<std::vector<double>> by_subject(static_cast<std::size_t>(t),
                                              std::vector<double>(static_cast<std::size_t>(n), 0));
  std::vector<double> by_pair(static_cast<std::size_t>(pair_count(t)), 0);
  double total_squares = 0;
  for (int l = 0; l < n; ++l)
    for (int i = 0; i < t; ++i)
      for (int j = i + 1; j < t; ++j) {
        const double x = ratings.ratings[static_cast<std::size_t>(l)]
                                        [static_cast<std::size_t>(pair_index(i, j, t))];
        by_subject[static_cast<std::size_t>(i)][static_cast<std::size_t>(l)] += x;
        by_subject[static_cast<std::size_t>(j)][static_cast<std::size_t>(l)] -= x;
        by_pair[static_cast<std::size_t>(pair_index(i, j, t))] += x;
        total_squares += x * x;
      }

  PairedComparisonAnalysis a;
  a.conditions = t;
  a.subjects = n;
  double main_squares = 0, subject_squares = 0;
  for (int i = 0; i < t; ++i) {
    double condition_total = 0;
    for (double x : by_subject[static_cast<std::size_t>(i)]) {
      condition_total += x;
      subject_squares += x * x;
    }
    a.scale.push_back(condition_total / (t * n));
    main_squares += condition_total * condition_total;
  }
  double pair_squares = 0;
  for (double x : by_pair) pair_squares += x * x;

  const double s_main = main_squares / (t * n);
  const double s_by_subject = subject_squares / t - s_main;
  const double s_combination = pair_squares / n - s_main;
  const double s_error = total_squares - s_main - s_by_subject - s_combination;
  const double df_main = t - 1, df_by_subject = (t - 1.0) * (n - 1),
               df_combination = (t - 1.0) * (t - 2) / 2;
  const double df_total = n * pair_count(t);
  const double df_error = df_total - df_main - df_by_subject - df_combination;

  // Round-off can leave an exactly consistent set of ratings a tiny negative error.
  a.error = untested(std::max(0.0, s_error), df_error);
  a.main_effect = tested(s_main, df_main, a.error);
  a.main_by_subject = tested(s_by_subject, df_by_subject, a.error);
  a.combination = tested(s_combination, df_combination, a.error);
  a.total = untested(total_squares, df_total);
  const double standard_error = std::sqrt(a.error.mean_square / (t * n));
  a.yardstick_05 = studentized_range_quantile(0.95, t, df_error) * standard_error;
  a.yardstick_01 = studentized_range_quantile(0.99, t, df_error) * standard_error;
  return a;
}

std::vector<FactorEffect> factor_effects(const PairedComparisonAnalysis& analysis,
                                         const std::vector<std::string>& factor_names,
                                         const std::vector<int>& level_count,
                                         const std::vector<std::vector<int>>& level_of) {
  const int t = analysis.conditions;
  const std::size_t factors = factor_names.size();
  if (level_count.size() != factors)
    throw Error("factor effects: a level count is needed for every factor");
  if (level_of.size() != static_cast<std::size_t>(t))
    throw Error(fmt::format("factor effects: levels given for {} conditions, the analysis has {}",
                            level_of.size(), t));
  long combinations = 1;
  for (int levels : level_count) {
    if (levels < 2) throw Error("factor effects: every factor needs at least 2 levels");
    combinations *= levels;
  }
  std::set<std::vector<int>> seen;
  for (int i = 0; i < t; ++i) {
    const auto& levels = level_of[static_cast<std::size_t>(i)];
    if (levels.size() != factors)
      throw Error(fmt::format("factor effects: condition {} has {} levels, not {}", i + 1,
                              levels.size(), factors));
    for (std::size_t f = 0; f < factors; ++f)
      if (levels[f] < 0 || levels[f] >= level_count[f])
        throw Error(fmt::format("factor effects: condition {}'s level {} of {} is outside 0..{}",
                                i + 1, levels[f], factor_names[f], level_count[f] - 1));
    if (!seen.insert(levels).second)
      throw Error(
          fmt::format("factor effects: condition {} repeats a combination of levels", i + 1));
  }
  if (combinations != t)
    throw Error(
        fmt::format("factor effects: the factors make {} combinations, not the {} conditions",
                    combinations, t));

  const double weight =
      static_cast<double>(t) * analysis.subjects;  // S = tN * (squared norm of the projection)
  std::vector<FactorEffect> effects;
  double explained = 0, explained_df = 0;
  for (std::size_t f = 0; f < factors; ++f) {
    const int levels = level_count[f];
    FactorEffect effect{
        factor_names[f], std::vector<double>(static_cast<std::size_t>(levels), 0), {}};
    for (int i = 0; i < t; ++i)
      effect.level_scale[static_cast<std::size_t>(level_of[static_cast<std::size_t>(i)][f])] +=
          analysis.scale[static_cast<std::size_t>(i)] * levels / t;
    double squares = 0;
    for (double mean : effect.level_scale) squares += mean * mean;
    const double sum_of_squares = weight * (static_cast<double>(t) / levels) * squares;
    effect.source = tested(sum_of_squares, levels - 1, analysis.error);
    explained += sum_of_squares;
    explained_df += levels - 1;
    effects.push_back(std::move(effect));
  }
  if (factors > 1) {
    const double left = std::max(0.0, analysis.main_effect.sum_of_squares - explained);
    effects.push_back(
        {"interaction",
         {},
         tested(left, analysis.main_effect.degrees_of_freedom - explained_df, analysis.error)});
  }
  return effects;
}

}  // namespace cohaptic
