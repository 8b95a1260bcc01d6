#include "common/study/simulated_rater.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "common/util/error.h"

namespace cohaptic {
namespace {

// Stiffness (compliance) discrimination: Weber fractions of about 15-22 % are commonly reported
// in the psychophysics literature (some studies report up to ~25 %). We take the low end: the
// subject switches back and forth between A and B on the same object, which favours
// discrimination.
constexpr double kHardnessJnd = 0.15;

// No published JND exists for a force's update rate itself. A force held between updates is
// felt as a vibration at the update rate, so we borrow the Weber fraction of vibrotactile
// frequency discrimination, commonly reported around 20-30 %.
constexpr double kFinenessJnd = 0.25;

// Judgement noise of one JND: a difference of exactly one JND is graded >= +1 half the time and
// reversed (z <= -1) only when the noise is below -2 sd (~2 %), so a JND is noticed, but not
// reliably; repeated ratings of one pair spread over about two grades, as subjects' do.
constexpr double kNoiseSdJnds = 1.0;

// The measure's value, checked: NaN, infinite or negative throws Error naming the measure and,
// when given, the trial.
double usable_measure(double value, std::string_view measure, std::string_view trial) {
  if (std::isfinite(value) && value >= 0) return value;
  const std::string where = trial.empty() ? std::string() : fmt::format("{} trial: ", trial);
  if (std::isnan(value))
    throw Error(fmt::format("{}{} is NaN (nothing to measure in the trial), so it cannot be rated",
                            where, measure));
  throw Error(fmt::format("{}{} must be finite and >= 0, got {}", where, measure, value));
}

// Fineness: the force update rate on a log scale (difference_in_jnds takes the log ratio),
// saturating at kContinuousForceRateHz. Why the update rate: P0 updates the force only when
// the simulation steps, so under step delay the force moves in steps at the (dropping)
// simulation rate, while P1 updates it every haptic tick (1 kHz); the rate is exactly what the
// protocols change. Why saturating: above a few hundred Hz the steps of a force updated that
// often are no longer felt as steps (vibrotactile sensitivity peaks near 250 Hz and falls
// steeply above), so 500 Hz and 1 kHz feel equally continuous.
double perceived_fineness(const TrialMeasures& measures, std::string_view trial) {
  return std::min(usable_measure(measures.force_update_rate_hz, "force_update_rate_hz", trial),
                  kContinuousForceRateHz);
}

// Hardness: the terminal force ratio f'/f_max, the paper's own hardness measure. The stiffness
// felt at the deepest point of a press is |F(k*)| / depth = terminal_force_ratio * f_max /
// depth; two conditions on the same object pressed the same way share f_max / depth, so the
// ratio of the two felt stiffnesses is the ratio of their terminal force ratios. Shift delay
// lowers it (cos(w tau) for a sinusoidal press). The alternatives go wrong under shift delay:
// effective_stiffness_n_per_m RISES with it (a stroke, and its displacement, start only when
// the delayed force arrives, and the force keeps rising after the hand has stopped: for the
// 1 Hz, 10 mm sinusoidal press of a 500 N/m spring, 500 N/m at tau = 0 but 675 N/m at 50 ms),
// and peak_force_n is set mostly by the hand (the studies' 300 N/m hand spring against the
// cube's ~9.5 N/mm) and is the maximum, which a delay shifts in time but does not lower.
// The limit: objects of different stiffness pressed without delay both score 1.
double perceived_hardness(const TrialMeasures& measures, std::string_view trial) {
  return usable_measure(measures.terminal_force_ratio, "terminal_force_ratio", trial);
}

double magnitude_in_trial(RatedQuality quality, const TrialMeasures& measures,
                          std::string_view trial) {
  switch (quality) {
    case RatedQuality::finer:
      return perceived_fineness(measures, trial);
    case RatedQuality::harder:
      return perceived_hardness(measures, trial);
  }
  throw Error(fmt::format("unknown rated quality {}", static_cast<int>(quality)));
}

// One grade per whole JND, toward zero (a difference below one JND is not noticed), within
// the scale. Odd in z, so it keeps the rating antisymmetric.
int grade_of_jnds(double z, int grades) {
  const double limit = static_cast<double>(grades);
  return static_cast<int>(std::trunc(std::clamp(z, -limit, limit)));
}

}  // namespace

RatedQuality parse_rated_quality(std::string_view text) {
  if (text == "finer") return RatedQuality::finer;
  if (text == "harder") return RatedQuality::harder;
  throw Error(fmt::format("unknown rated quality '{}' (expected finer or harder)", text));
}

const char* to_string(RatedQuality quality) {
  switch (quality) {
    case RatedQuality::finer:
      return "finer";
    case RatedQuality::harder:
      return "harder";
  }
  return "?";
}

SimulatedRaterSettings default_rater_settings(RatedQuality quality, unsigned seed) {
  SimulatedRaterSettings settings;
  settings.quality = quality;
  settings.just_noticeable_difference =
      quality == RatedQuality::harder ? kHardnessJnd : kFinenessJnd;
  settings.noise_sd = kNoiseSdJnds;
  settings.seed = seed;
  return settings;
}

void validate(const SimulatedRaterSettings& settings) {
  if (settings.quality != RatedQuality::finer && settings.quality != RatedQuality::harder)
    throw Error(fmt::format("unknown rated quality {}", static_cast<int>(settings.quality)));
  if (!(settings.just_noticeable_difference > 0) ||
      !std::isfinite(settings.just_noticeable_difference))
    throw Error(
        fmt::format("just-noticeable difference must be a finite Weber fraction > 0, got {}",
                    settings.just_noticeable_difference));
  if (!(settings.noise_sd >= 0) || !std::isfinite(settings.noise_sd))
    throw Error(
        fmt::format("rater noise sd must be finite and >= 0 JNDs, got {}", settings.noise_sd));
  if (settings.grades < 1)
    throw Error(
        fmt::format("the rating scale needs at least 1 grade each side, got {}", settings.grades));
}

std::mt19937 rater_rng(const SimulatedRaterSettings& settings) {
  return std::mt19937(settings.seed);
}

double perceived_magnitude(RatedQuality quality, const TrialMeasures& measures) {
  return magnitude_in_trial(quality, measures, "");
}

double difference_in_jnds(const SimulatedRaterSettings& settings, const TrialMeasures& first,
                          const TrialMeasures& second) {
  validate(settings);
  const double m_first = magnitude_in_trial(settings.quality, first, "first");
  const double m_second = magnitude_in_trial(settings.quality, second, "second");
  // Equal (both 0 included, where the log ratio would be 0/0): no difference at all.
  if (m_first == m_second) return 0;
  return std::log(m_first / m_second) / std::log1p(settings.just_noticeable_difference);
}

int rate_pair(const SimulatedRaterSettings& settings, const TrialMeasures& first,
              const TrialMeasures& second, std::mt19937& rng) {
  const double d = difference_in_jnds(settings, first, second);
  // A fresh distribution each call: no draw cached from an earlier call carries over.
  std::normal_distribution<double> standard_normal(0, 1);
  const double noise = settings.noise_sd * standard_normal(rng);
  return grade_of_jnds(d + noise, settings.grades);
}

}  // namespace cohaptic
