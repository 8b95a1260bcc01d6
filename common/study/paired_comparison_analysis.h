// Scheffe's analysis of variance for paired comparisons, in Nakaya's modification: each of N
// subjects rates every pair (i, j), i < j, of t conditions once, on a graded scale (the
// paper's five grades +2 ... -2), whichever of the two was presented first. With x_ijl
// subject l's rating of (i, j) and x_jil = -x_ijl, the model
//     x_ijl = (alpha_i + alpha_il) - (alpha_j + alpha_jl) + gamma_ij + e_ijl,
//     sum_i alpha_i = 0, sum_i alpha_il = 0, gamma_ij = -gamma_ji, sum_j gamma_ij = 0
// gives each condition's scale value alpha_i (in the scale's grades; a positive rating
// raises the pair's first condition), and splits the ratings' sum of squares into the main
// effect (alpha: do the conditions differ?), main effect x subject (alpha_il: do subjects
// order them differently?), the combination effect (gamma: do pairs depart from the scale's
// differences?) and error, each tested by F against the error. Two conditions differ at
// level phi when their scale values differ by more than the yardstick
//     Y_phi = q(1 - phi; t, f_e) sqrt(V_e / (t N)),
// q the studentized range's upper point (studentized_range.h), f_e and V_e the error's
// degrees of freedom and mean square. Formulas as in Sato, "Statistical methods of sensory
// tests" (JUSE, 1985), chapter 20; the method: H. Scheffe, JASA 47 (1952) 381-400.
#pragma once

#include <string>
#include <vector>

namespace cohaptic {

/// Ratings of a paired-comparison study in Nakaya's design.
struct PairedComparisonRatings {
  int conditions = 0;  ///< t, at least 3
  /// ratings[l][pair_index(i, j)]: subject l's rating of pair (i, j), i < j; positive when
  /// condition i was felt more (finer, harder: as the question asks). At least 2 subjects.
  std::vector<std::vector<double>> ratings;
};

/// t (t - 1) / 2: the pairs of t conditions, each rated once per subject.
int pair_count(int conditions);
/// Where pair (first, second), first < second, sits in a subject's ratings: (0,1), (0,2),
/// ..., (0,t-1), (1,2), ... in order.
int pair_index(int first, int second, int conditions);

/// One line of the analysis-of-variance table. `f` and `p` (the upper tail of F against
/// the error) are NaN for the error and the total lines.
struct VarianceSource {
  double sum_of_squares = 0;
  double degrees_of_freedom = 0;
  double mean_square = 0;
  double f = 0;
  double p = 0;
};

struct PairedComparisonAnalysis {
  int conditions = 0;
  int subjects = 0;
  std::vector<double> scale;  ///< alpha_i per condition; they sum to 0
  VarianceSource main_effect, main_by_subject, combination, error, total;
  double yardstick_05 = 0;  ///< Y(0.05): scale values further apart differ at the 5 % level
  double yardstick_01 = 0;  ///< Y(0.01)
};

/// The analysis above. Throws Error naming the problem for fewer than 3 conditions or 2
/// subjects, a subject with the wrong number of ratings, or a rating that is not finite.
PairedComparisonAnalysis analyse_paired_comparisons(const PairedComparisonRatings& ratings);

/// A factor's share of the main effect when the conditions are a full factorial design
/// (every combination of the factors' levels exactly once).
struct FactorEffect {
  std::string name;                 ///< the factor's name, or "interaction" for what is left
  std::vector<double> level_scale;  ///< the mean scale value of the conditions at each level (empty
                                    ///< for the interaction)
  VarianceSource source;  ///< its sum of squares, degrees of freedom and F test against the error
};

/// The main effect split into each factor's (from its levels' mean scale values, weighted
/// by the conditions at each level) and the interaction left over, each with its F test.
/// `level_of[i][f]`: condition i's level of factor f, 0 <= level < level_count[f]. Throws
/// Error when the conditions are not the full factorial of the levels.
std::vector<FactorEffect> factor_effects(const PairedComparisonAnalysis& analysis,
                                         const std::vector<std::string>& factor_names,
                                         const std::vector<int>& level_count,
                                         const std::vector<std::vector<int>>& level_of);

}  // namespace cohaptic
