// A simulated rater for paired comparisons: it turns the objective measures of two trials
// (measures.h) into the grade a subject would give on the paper's five-grade scale, to
// rehearse a study and its analysis (paired_comparison_analysis.h) without people.
//
// The model. Each quality has a perceived magnitude m >= 0 on a ratio scale
// (perceived_magnitude()); two trials differ by
//     d = ln(m_first / m_second) / ln(1 + JND)     [JNDs]
// (Weber's law: equal ratios are equally noticeable, and a ratio of 1 + JND is one JND). The
// rater adds noise, z = d + noise_sd * N(0, 1), and grades one step per whole JND, rounding
// toward zero and clamping: |z| < 1 gives 0 (not noticed), 1 <= |z| < 2 gives +/-1, ...,
// |z| >= grades gives +/-grades. Positive: the FIRST trial felt more (finer, harder).
//
// Invariants: without noise, equal trials rate 0, a difference below one JND rates 0, and the
// rating is odd in d (swapping the trials negates it) and non-decreasing in d; with noise,
// the same holds for the expected rating, since the noise is symmetric and the grading odd.
// A measure the quality needs that is NaN, infinite or negative throws Error naming it and the
// trial; measures the quality does not use are not looked at.
#pragma once

#include <random>
#include <string_view>

#include "common/study/measures.h"

namespace cohaptic {

/// The question the subject answers: "which felt finer?" (smoothness of the force) or
/// "which felt harder?" (stiffness of the pressed object).
enum class RatedQuality { finer, harder };

RatedQuality parse_rated_quality(std::string_view text);  ///< "finer" or "harder"; throws Error
const char* to_string(RatedQuality quality);

struct SimulatedRaterSettings {
  RatedQuality quality = RatedQuality::finer;
  /// Weber fraction: the perceived magnitudes' ratio 1 + JND is one grade's worth [1]. > 0.
  double just_noticeable_difference = 0;
  /// Standard deviation of the judgement noise, in JNDs. >= 0 (0: a deterministic rater).
  double noise_sd = 0;
  /// Seed of the rater's own random stream (rater_rng()); rate_pair() draws from the stream it
  /// is given, so a session may share one.
  unsigned seed = 0;
  /// The scale runs from -grades to +grades (the paper's five grades: 2). >= 1.
  int grades = 2;
};

/// The documented defaults for one quality (see simulated_rater.cpp for the figures and why).
SimulatedRaterSettings default_rater_settings(RatedQuality quality, unsigned seed = 0);

/// Throws Error naming the first bad setting.
void validate(const SimulatedRaterSettings& settings);

/// std::mt19937 seeded with settings.seed.
std::mt19937 rater_rng(const SimulatedRaterSettings& settings);

/// Update rates at or above this feel continuous: the perceived fineness stops growing [Hz].
inline constexpr double kContinuousForceRateHz = 500;

/// The perceived magnitude of `quality` in one trial, on a ratio scale (>= 0; only ratios of
/// two trials' magnitudes matter):
///   finer:  min(force_update_rate_hz, kContinuousForceRateHz) [Hz]
///   harder: terminal_force_ratio [1]
/// Throws Error naming the measure when it is NaN, infinite or negative.
double perceived_magnitude(RatedQuality quality, const TrialMeasures& measures);

/// d above: how many JNDs more of settings.quality the first trial has than the second
/// (negative: less). +/-infinity when exactly one magnitude is 0; 0 when both are equal.
double difference_in_jnds(const SimulatedRaterSettings& settings, const TrialMeasures& first,
                          const TrialMeasures& second);

/// The grade in [-grades, +grades] the rater gives "first" against "second" (positive: the
/// first felt finer / harder). Draws one fresh standard normal from `rng`, so the rating
/// depends only on the settings, the measures and the state of `rng`. Throws Error for bad
/// settings, or naming the trial ("first"/"second") and the measure when a needed measure is
/// NaN, infinite or negative.
int rate_pair(const SimulatedRaterSettings& settings, const TrialMeasures& first,
              const TrialMeasures& second, std::mt19937& rng);

}  // namespace cohaptic
