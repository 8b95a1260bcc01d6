// Scheffe's paired comparisons in Nakaya's modification (paired_comparison_analysis.h):
// against a published worked example, and against a second computation of the same model by
// least squares (nested fits with Eigen's complete orthogonal decomposition) to 1e-9.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>

#include "common/study/paired_comparison_analysis.h"
#include "common/util/error.h"

namespace cohaptic {
namespace {

// Worked example of Nakaya's modification: 3 stimuli, 6 subjects, ratings of the pairs
// (1,2), (1,3), (2,3), a positive rating favouring the pair's first stimulus. Data and
// results from MARUI Atsushi, "Scheffe's paired comparison (Nakaya's modification)", 2012
// (https://marui.hatenablog.com/entry/20120912/1347435796), computed as in Sato,
// "Statistical methods of sensory tests" (JUSE, 1985), chapter 20. The published figures
// have 4 decimals.
TEST(PairedComparisonAnalysis, ReproducesAPublishedWorkedExample) {
  const PairedComparisonRatings ratings{
      3, {{-2, -1, 1}, {-2, -2, 2}, {-3, 0, 3}, {-3, 0, 2}, {-1, 1, 2}, {-3, -1, 0}}};
  const PairedComparisonAnalysis a = analyse_paired_comparisons(ratings);
  constexpr double kPublished = 0.5e-4;  // half the last published digit
  EXPECT_NEAR(a.scale[0], -0.9444, kPublished);
  EXPECT_NEAR(a.scale[1], 1.3333, kPublished);
  EXPECT_NEAR(a.scale[2], -0.3889, kPublished);
  const struct {
    const VarianceSource& source;
    double ss, df, ms, f, p;
  } lines[] = {{a.main_effect, 50.7778, 2, 25.3889, 43.1132, 0.0007},
               {a.main_by_subject, 11.2222, 10, 1.1222, 1.9057, 0.2470},
               {a.combination, 0.0556, 1, 0.0556, 0.0943, 0.7711}};
  for (const auto& line : lines) {
    EXPECT_NEAR(line.source.sum_of_squares, line.ss, kPublished);
    EXPECT_EQ(line.source.degrees_of_freedom, line.df);
    EXPECT_NEAR(line.source.mean_square, line.ms, kPublished);
    EXPECT_NEAR(line.source.f, line.f, kPublished);
    EXPECT_NEAR(line.source.p, line.p, kPublished);
  }
  EXPECT_NEAR(a.error.sum_of_squares, 2.9444, kPublished);
  EXPECT_EQ(a.error.degrees_of_freedom, 5);
  EXPECT_NEAR(a.error.mean_square, 0.5889, kPublished);
  EXPECT_NEAR(a.total.sum_of_squares, 65, 1e-12);
  EXPECT_EQ(a.total.degrees_of_freedom, 18);
  EXPECT_TRUE(std::isnan(a.error.f) && std::isnan(a.total.p));
  // The published yardsticks came from R's qtukey, which stops within 1e-4 of q.
  EXPECT_NEAR(a.yardstick_05, 0.8323, 1e-4);
  EXPECT_NEAR(a.yardstick_01, 1.2617, 1e-4);
}

// ||y - X X^+ y||^2: what a least-squares fit of y on X's columns leaves.
double residual_squares(const Eigen::MatrixXd& x, const Eigen::VectorXd& y) {
  return (y - x * x.completeOrthogonalDecomposition().solve(y)).squaredNorm();
}

// Random ratings of t conditions by n subjects on the five grades, from conditions that
// differ, subjects that differ and noise.
PairedComparisonRatings random_ratings(int t, int n, unsigned seed) {
  std::mt19937 random(seed);
  std::normal_distribution<double> normal;
  std::vector<double> truth(static_cast<std::size_t>(t));
  for (double& value : truth) value = normal(random);
  PairedComparisonRatings ratings{t, {}};
  for (int l = 0; l < n; ++l) {
    auto& subject = ratings.ratings.emplace_back(static_cast<std::size_t>(pair_count(t)));
    const double gain = 0.5 + 0.2 * l;
    for (int i = 0; i < t; ++i)
      for (int j = i + 1; j < t; ++j)
        subject[static_cast<std::size_t>(pair_index(i, j, t))] =
            std::clamp(std::round(gain * (truth[static_cast<std::size_t>(i)] -
                                          truth[static_cast<std::size_t>(j)]) +
                                  normal(random)),
                       -2.0, 2.0);
  }
  return ratings;
}

// The same model fitted by least squares, one term at a time: the scale values are the
// minimum-norm fit of alpha (which sums to 0), and each sum of squares what adding its term
// removes from the residual (main effect; its deviations per subject; a free mean per pair,
// which holds the main effect and the combination effect).
TEST(PairedComparisonAnalysis, EqualsALeastSquaresFitOfTheSameModel) {
  for (const auto& [t, n, seed] :
       {std::tuple{3, 2, 1u}, std::tuple{5, 7, 2u}, std::tuple{6, 10, 3u}}) {
    SCOPED_TRACE(::testing::Message() << t << " conditions, " << n << " subjects");
    const PairedComparisonRatings ratings = random_ratings(t, n, seed);
    const int pairs = pair_count(t), rows = n * pairs;
    Eigen::VectorXd y(rows);
    Eigen::MatrixXd main = Eigen::MatrixXd::Zero(rows, t),
                    by_subject = Eigen::MatrixXd::Zero(rows, t * n),
                    pair = Eigen::MatrixXd::Zero(rows, pairs);
    for (int l = 0; l < n; ++l)
      for (int i = 0; i < t; ++i)
        for (int j = i + 1; j < t; ++j) {
          const int p = pair_index(i, j, t), row = l * pairs + p;
          y(row) = ratings.ratings[static_cast<std::size_t>(l)][static_cast<std::size_t>(p)];
          main(row, i) = 1;
          main(row, j) = -1;
          by_subject(row, l * t + i) = 1;
          by_subject(row, l * t + j) = -1;
          pair(row, p) = 1;
        }
    Eigen::MatrixXd with_subjects(rows, t + t * n), full(rows, t + t * n + pairs);
    with_subjects << main, by_subject;
    full << main, by_subject, pair;
    const double total = y.squaredNorm(), after_main = residual_squares(main, y),
                 after_subjects = residual_squares(with_subjects, y),
                 after_pairs = residual_squares(full, y);

    const PairedComparisonAnalysis a = analyse_paired_comparisons(ratings);
    const Eigen::VectorXd alpha = main.completeOrthogonalDecomposition().solve(y);
    for (int i = 0; i < t; ++i) EXPECT_NEAR(a.scale[static_cast<std::size_t>(i)], alpha(i), 1e-9);
    EXPECT_NEAR(a.main_effect.sum_of_squares, total - after_main, 1e-9);
    EXPECT_NEAR(a.main_by_subject.sum_of_squares, after_main - after_subjects, 1e-9);
    EXPECT_NEAR(a.combination.sum_of_squares, after_subjects - after_pairs, 1e-9);
    EXPECT_NEAR(a.error.sum_of_squares, after_pairs, 1e-9);
    EXPECT_EQ(a.error.degrees_of_freedom,
              rows - (t - 1) - (t - 1) * (n - 1) - (t - 1) * (t - 2) / 2);
  }
}

// Conditions that are the full factorial of two factors: the factors' sums of squares and
// the interaction's add up to the main effect, and each factor's equals a least-squares fit
// of the ratings on that factor's levels alone.
TEST(PairedComparisonAnalysis, SplitsTheMainEffectIntoFactorsOfAFullFactorial) {
  const int t = 6, n = 8;  // protocol (2 levels) x step nodes (3 levels)
  const PairedComparisonRatings ratings = random_ratings(t, n, 4);
  const PairedComparisonAnalysis a = analyse_paired_comparisons(ratings);
  std::vector<std::vector<int>> level_of;
  for (int protocol = 0; protocol < 2; ++protocol)
    for (int step = 0; step < 3; ++step) level_of.push_back({protocol, step});
  const std::vector<FactorEffect> effects =
      factor_effects(a, {"protocol", "step_nodes"}, {2, 3}, level_of);
  ASSERT_EQ(effects.size(), 3u);
  EXPECT_EQ(effects[2].name, "interaction");
  EXPECT_NEAR(effects[0].source.sum_of_squares + effects[1].source.sum_of_squares +
                  effects[2].source.sum_of_squares,
              a.main_effect.sum_of_squares, 1e-9);
  EXPECT_EQ(effects[2].source.degrees_of_freedom, 2);

  const int pairs = pair_count(t), rows = n * pairs;
  for (std::size_t f = 0; f < 2; ++f) {
    const int levels = f == 0 ? 2 : 3;
    Eigen::VectorXd y(rows);
    Eigen::MatrixXd x = Eigen::MatrixXd::Zero(rows, levels);
    for (int l = 0; l < n; ++l)
      for (int i = 0; i < t; ++i)
        for (int j = i + 1; j < t; ++j) {
          const int row = l * pairs + pair_index(i, j, t);
          y(row) = ratings.ratings[static_cast<std::size_t>(l)]
                                  [static_cast<std::size_t>(pair_index(i, j, t))];
          x(row, level_of[static_cast<std::size_t>(i)][f]) += 1;
          x(row, level_of[static_cast<std::size_t>(j)][f]) -= 1;
        }
    EXPECT_NEAR(effects[f].source.sum_of_squares, y.squaredNorm() - residual_squares(x, y), 1e-9)
        << effects[f].name;
    EXPECT_EQ(effects[f].level_scale.size(), static_cast<std::size_t>(levels));
  }
  EXPECT_THROW(factor_effects(a, {"protocol"}, {2}, std::vector<std::vector<int>>(6, {0})), Error)
      << "not a full factorial";
}

TEST(PairedComparisonAnalysis, RatingsThatCannotBeAnalysedAreRefused) {
  EXPECT_THROW(analyse_paired_comparisons({2, {{1}, {-1}}}), Error) << "two conditions";
  EXPECT_THROW(analyse_paired_comparisons({3, {{1, 0, 2}}}), Error) << "one subject";
  EXPECT_THROW(analyse_paired_comparisons({3, {{1, 0, 2}, {1, 0}}}), Error) << "a rating missing";
  EXPECT_THROW(analyse_paired_comparisons({3, {{1, 0, 2}, {1, std::nan(""), 0}}}), Error)
      << "not a number";
}

TEST(PairedComparisonAnalysis, PairsAreIndexedInOrder) {
  int expected = 0;
  for (int i = 0; i < 5; ++i)
    for (int j = i + 1; j < 5; ++j) EXPECT_EQ(pair_index(i, j, 5), expected++);
  EXPECT_EQ(expected, pair_count(5));
}

}  // namespace
}  // namespace cohaptic
