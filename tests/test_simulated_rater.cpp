// The simulated rater (common/study/simulated_rater.h) against its contract: equal trials and
// sub-JND differences rate 0 without noise, large ones saturate, the rating is monotone and
// (in expectation) antisymmetric, a P1-like force rates finer than a P0-like one, a prompt
// press harder than a shift-delayed one (also through measure_trial on synthetic traces), and
// NaN measures or bad settings throw naming what was wrong.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <functional>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "common/study/force_trace.h"
#include "common/study/measures.h"
#include "common/study/simulated_rater.h"
#include "common/util/error.h"
#include "common/util/not_a_number.h"

namespace cohaptic {
namespace {

constexpr double kPi = std::numbers::pi;

TrialMeasures with_update_rate(double hz) {
  TrialMeasures m;
  m.force_update_rate_hz = hz;
  return m;
}

TrialMeasures with_terminal_ratio(double ratio) {
  TrialMeasures m;
  m.terminal_force_ratio = ratio;
  return m;
}

// Measures of the quality's magnitude `value`.
TrialMeasures with_magnitude(RatedQuality quality, double value) {
  return quality == RatedQuality::finer ? with_update_rate(value) : with_terminal_ratio(value);
}

SimulatedRaterSettings noiseless(RatedQuality quality, int grades = 2) {
  SimulatedRaterSettings s = default_rater_settings(quality);
  s.noise_sd = 0;
  s.grades = grades;
  return s;
}

// A reference magnitude for each quality, below the fineness saturation.
double reference(RatedQuality quality) { return quality == RatedQuality::finer ? 100 : 0.8; }

// The magnitude `jnds` JNDs above the reference.
double jnds_above(const SimulatedRaterSettings& s, double jnds) {
  return reference(s.quality) * std::pow(1 + s.just_noticeable_difference, jnds);
}

int rate(const SimulatedRaterSettings& s, double first, double second, unsigned seed = 1) {
  std::mt19937 rng(seed);
  return rate_pair(s, with_magnitude(s.quality, first), with_magnitude(s.quality, second), rng);
}

double mean_rating(const SimulatedRaterSettings& s, const TrialMeasures& first,
                   const TrialMeasures& second, int draws, unsigned seed) {
  std::mt19937 rng(seed);
  double sum = 0;
  for (int i = 0; i < draws; ++i) sum += rate_pair(s, first, second, rng);
  return sum / draws;
}

const RatedQuality kQualities[] = {RatedQuality::finer, RatedQuality::harder};

TEST(SimulatedRaterQuality, ParsesAndPrintsItsNames) {
  for (RatedQuality q : kQualities) EXPECT_EQ(parse_rated_quality(to_string(q)), q);
  EXPECT_STREQ(to_string(RatedQuality::finer), "finer");
  EXPECT_STREQ(to_string(RatedQuality::harder), "harder");
  EXPECT_THROW(parse_rated_quality("softer"), Error);
  EXPECT_THROW(parse_rated_quality("Finer"), Error);
}

TEST(SimulatedRaterDefaults, AreTheDocumentedWeberFractionsAndValid) {
  const SimulatedRaterSettings hard = default_rater_settings(RatedQuality::harder, 7);
  EXPECT_EQ(hard.quality, RatedQuality::harder);
  EXPECT_EQ(hard.just_noticeable_difference, 0.15);
  EXPECT_EQ(hard.seed, 7u);
  EXPECT_EQ(hard.grades, 2);
  const SimulatedRaterSettings fine = default_rater_settings(RatedQuality::finer);
  EXPECT_EQ(fine.just_noticeable_difference, 0.25);
  for (const SimulatedRaterSettings& s : {hard, fine}) {
    EXPECT_EQ(s.noise_sd, 1.0);
    EXPECT_NO_THROW(validate(s));
  }
  // The rater's own stream is std::mt19937 seeded with the seed.
  std::mt19937 expected(7);
  EXPECT_EQ(rater_rng(hard)(), expected());
}

TEST(SimulatedRaterProperties, EqualMeasuresWithoutNoiseRateZero) {
  for (RatedQuality q : kQualities)
    for (double value : {0.0, 0.3, 1.0, 50.0, 1000.0})
      EXPECT_EQ(rate(noiseless(q), value, value), 0) << value;
}

TEST(SimulatedRaterProperties, DifferencesBelowOneJndRateZeroWithoutNoise) {
  for (RatedQuality q : kQualities) {
    const SimulatedRaterSettings s = noiseless(q);
    for (double jnds : {0.3, 0.6, 0.99}) {
      EXPECT_EQ(rate(s, jnds_above(s, jnds), reference(q)), 0) << to_string(q) << " " << jnds;
      EXPECT_EQ(rate(s, reference(q), jnds_above(s, jnds)), 0) << to_string(q) << " " << jnds;
    }
    // One JND and a little more is noticed, both ways round.
    EXPECT_EQ(rate(s, jnds_above(s, 1.01), reference(q)), 1) << to_string(q);
    EXPECT_EQ(rate(s, reference(q), jnds_above(s, 1.01)), -1) << to_string(q);
  }
}

TEST(SimulatedRaterProperties, LargeDifferencesSaturateAtTheScalesEnds) {
  for (RatedQuality q : kQualities)
    for (int grades : {1, 2, 3}) {
      const SimulatedRaterSettings s = noiseless(q, grades);
      // (Just above `grades` JNDs: exactly on a boundary, the log's round-off decides.)
      for (double jnds : {grades + 0.01, grades + 0.5, 10.0, 40.0}) {
        EXPECT_EQ(rate(s, jnds_above(s, jnds), reference(q)), grades)
            << to_string(q) << " " << jnds;
        EXPECT_EQ(rate(s, reference(q), jnds_above(s, jnds)), -grades)
            << to_string(q) << " " << jnds;
      }
      // A zero magnitude against any other is as far apart as the scale goes.
      EXPECT_EQ(rate(s, reference(q), 0), grades);
      EXPECT_EQ(rate(s, 0, reference(q)), -grades);
      // And with noise the rating never leaves the scale.
      SimulatedRaterSettings noisy = s;
      noisy.noise_sd = 5;
      std::mt19937 rng(3);
      for (int i = 0; i < 2000; ++i) {
        const int r = rate_pair(noisy, with_magnitude(q, jnds_above(s, 1)),
                                with_magnitude(q, reference(q)), rng);
        EXPECT_LE(std::abs(r), grades);
      }
    }
}

TEST(SimulatedRaterProperties, MonotoneInTheDifference) {
  for (RatedQuality q : kQualities) {
    SimulatedRaterSettings s = noiseless(q);
    for (double noise_sd : {0.0, 1.0}) {
      s.noise_sd = noise_sd;
      // Each draw with the same rng state (common random numbers): the rating itself, not only
      // its mean, must not decrease as the first trial grows.
      for (unsigned seed = 1; seed <= 20; ++seed) {
        int previous = -s.grades;
        for (double jnds = -4; jnds <= 4; jnds += 0.125) {
          const int r = rate(s, jnds_above(s, jnds), reference(q), seed);
          EXPECT_GE(r, previous) << to_string(q) << " noise " << noise_sd << " seed " << seed
                                 << " at " << jnds;
          previous = r;
        }
      }
    }
  }
}

TEST(SimulatedRaterProperties, AntisymmetricInExpectation) {
  constexpr int kDraws = 20000;
  for (RatedQuality q : kQualities) {
    const SimulatedRaterSettings s = default_rater_settings(q);
    for (double jnds : {0.0, 0.4, 1.5, 2.7}) {
      const TrialMeasures a = with_magnitude(q, jnds_above(s, jnds)),
                          b = with_magnitude(q, reference(q));
      const double forward = mean_rating(s, a, b, kDraws, 11);
      const double backward = mean_rating(s, b, a, kDraws, 12);
      // Each mean's standard error is below 1.3 / sqrt(20000) ~ 0.009: 0.05 is > 3.5 SE of the sum.
      EXPECT_NEAR(forward + backward, 0, 0.05) << to_string(q) << " " << jnds;
      if (jnds >= 1.5) {
        EXPECT_GT(forward, 0.5) << to_string(q) << " " << jnds;  // not trivially 0
      }
    }
  }
}

TEST(SimulatedRaterProperties, DeterministicForAGivenRngState) {
  const SimulatedRaterSettings s = default_rater_settings(RatedQuality::harder);
  const TrialMeasures a = with_terminal_ratio(0.9),
                      b = with_terminal_ratio(0.8);  // 0.84 JNDs: noise decides
  std::mt19937 rng(5);
  std::vector<int> ratings;
  for (int i = 0; i < 201; ++i) {
    // The same state twice in a row gives the same rating and leaves the same state: nothing
    // from the first call (such as a cached second normal draw) reaches the second.
    std::mt19937 copy = rng;
    const int from_copy = rate_pair(s, a, b, copy);
    ratings.push_back(rate_pair(s, a, b, rng));
    EXPECT_EQ(ratings.back(), from_copy) << i;
    EXPECT_EQ(copy, rng) << i;
  }
  // The noise did matter: not every rating was the same.
  EXPECT_NE(std::count(ratings.begin(), ratings.end(), ratings.front()),
            static_cast<std::ptrdiff_t>(ratings.size()));
}

TEST(SimulatedRaterFiner, AP1LikeForceRatesFinerThanAP0LikeOne) {
  const TrialMeasures p1 = with_update_rate(1000), p0 = with_update_rate(50);
  EXPECT_EQ(rate(noiseless(RatedQuality::finer), 1000, 50), 2);
  EXPECT_EQ(rate(noiseless(RatedQuality::finer), 50, 1000), -2);
  const SimulatedRaterSettings s = default_rater_settings(RatedQuality::finer);
  EXPECT_GT(mean_rating(s, p1, p0, 1000, 1), 1.9);
  EXPECT_LT(mean_rating(s, p0, p1, 1000, 2), -1.9);
}

TEST(SimulatedRaterFiner, RatesAboveTheContinuousRateFeelTheSame) {
  const SimulatedRaterSettings s = noiseless(RatedQuality::finer);
  EXPECT_EQ(perceived_magnitude(RatedQuality::finer, with_update_rate(2000)),
            kContinuousForceRateHz);
  EXPECT_EQ(perceived_magnitude(RatedQuality::finer, with_update_rate(120)), 120);
  EXPECT_EQ(rate(s, 1000, kContinuousForceRateHz), 0);
  EXPECT_EQ(rate(s, 600, 1000), 0);
  // Below it, the log rate counts: 200 Hz against 500 Hz is ln(2.5) / ln(1.25) = 4.1 JNDs.
  EXPECT_NEAR(difference_in_jnds(s, with_update_rate(200), with_update_rate(1000)),
              -std::log(2.5) / std::log(1.25), 1e-12);
}

TEST(SimulatedRaterHarder, AStifferTrialRatesHarder) {
  // Terminal force ratios of a prompt press (1) and of one answered late (0.7): 2.55 JNDs.
  EXPECT_EQ(rate(noiseless(RatedQuality::harder), 1.0, 0.7), 2);
  EXPECT_EQ(rate(noiseless(RatedQuality::harder), 0.7, 1.0), -2);
  const SimulatedRaterSettings s = default_rater_settings(RatedQuality::harder);
  EXPECT_GT(mean_rating(s, with_terminal_ratio(1.0), with_terminal_ratio(0.7), 2000, 1), 1);
}

// End to end through measure_trial. One press x(t) = A sin(w t) into the object (along -z) for
// half a period of 0.5 s, answered by a spring force k A sin(w (t' - tau)) shifted by tau and
// recomputed only every `hold` samples (t' the time of the last update), sampled at 1 kHz.
ForceTrace press(double tau, std::size_t hold) {
  constexpr double kA = 0.01, kK = 500, kOmega = 2 * kPi, kDt = 1e-3;
  const auto n = static_cast<std::size_t>(std::lround((0.5 + tau) / kDt)) + 2;
  ForceTrace trace;
  for (std::size_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) * kDt;
    const double u = static_cast<double>(k / hold * hold) * kDt - tau;
    trace.time_s.push_back(t);
    trace.force.emplace_back(0, 0, u > 0 && u < 0.5 ? kK * kA * std::sin(kOmega * u) : 0);
    trace.position.emplace_back(0, 0, t > 0 && t < 0.5 ? -kA * std::sin(kOmega * t) : 0);
  }
  return trace;
}

TEST(SimulatedRaterFromTraces, AShiftDelayedPressFeelsSofterAndAHeldForceCoarser) {
  const TrialMeasures prompt = measure_trial(press(0, 1));
  const TrialMeasures delayed =
      measure_trial(press(0.1, 1));  // terminal ratio cos(0.2 pi) = 0.81: 1.5 JNDs
  const TrialMeasures held = measure_trial(press(0, 20));  // a P0-like force at 50 Hz
  std::mt19937 rng(1);
  EXPECT_EQ(rate_pair(noiseless(RatedQuality::harder), prompt, delayed, rng), 1);
  EXPECT_EQ(rate_pair(noiseless(RatedQuality::harder), delayed, prompt, rng), -1);
  EXPECT_EQ(rate_pair(noiseless(RatedQuality::finer), prompt, held, rng), 2);
  EXPECT_EQ(rate_pair(noiseless(RatedQuality::finer), held, prompt, rng), -2);
  // A shift delay does not change how often the force is updated: not finer, not coarser.
  EXPECT_EQ(rate_pair(noiseless(RatedQuality::finer), prompt, delayed, rng), 0);
}

// The message of the Error `rating` throws ("" if none).
std::string error_of(const std::function<void()>& rating) {
  try {
    rating();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(SimulatedRaterErrors, ANaNMeasureThrowsNamingItAndTheTrial) {
  std::mt19937 rng(1);
  const SimulatedRaterSettings fine = default_rater_settings(RatedQuality::finer);
  const SimulatedRaterSettings hard = default_rater_settings(RatedQuality::harder);
  const TrialMeasures good = with_update_rate(100);
  TrialMeasures no_contact = with_update_rate(kNaN);
  no_contact.terminal_force_ratio = kNaN;

  std::string what = error_of([&] { rate_pair(fine, no_contact, good, rng); });
  EXPECT_NE(what.find("first trial"), std::string::npos) << what;
  EXPECT_NE(what.find("force_update_rate_hz"), std::string::npos) << what;
  EXPECT_NE(what.find("NaN"), std::string::npos) << what;

  what = error_of([&] { rate_pair(hard, with_terminal_ratio(0.9), no_contact, rng); });
  EXPECT_NE(what.find("second trial"), std::string::npos) << what;
  EXPECT_NE(what.find("terminal_force_ratio"), std::string::npos) << what;

  what = error_of([&] { perceived_magnitude(RatedQuality::harder, no_contact); });
  EXPECT_NE(what.find("terminal_force_ratio"), std::string::npos) << what;

  // Infinite or negative measures are as unusable as NaN.
  EXPECT_THROW(rate_pair(fine, with_update_rate(-1), good, rng), Error);
  EXPECT_THROW(rate_pair(fine, good, with_update_rate(INFINITY), rng), Error);

  // A measure the quality does not use may be NaN: a finer rating needs no hardness.
  TrialMeasures no_stroke = good;
  no_stroke.terminal_force_ratio = kNaN;
  EXPECT_NO_THROW(rate_pair(fine, no_stroke, good, rng));
}

TEST(SimulatedRaterErrors, BadSettingsThrow) {
  std::mt19937 rng(1);
  const TrialMeasures a = with_update_rate(100);
  const auto with = [](const std::function<void(SimulatedRaterSettings&)>& change) {
    SimulatedRaterSettings s = default_rater_settings(RatedQuality::finer);
    change(s);
    return s;
  };
  EXPECT_THROW(rate_pair(with([](auto& s) { s.just_noticeable_difference = 0; }), a, a, rng),
               Error);
  EXPECT_THROW(rate_pair(with([](auto& s) { s.just_noticeable_difference = kNaN; }), a, a, rng),
               Error);
  EXPECT_THROW(rate_pair(with([](auto& s) { s.noise_sd = -0.1; }), a, a, rng), Error);
  EXPECT_THROW(rate_pair(with([](auto& s) { s.noise_sd = kNaN; }), a, a, rng), Error);
  EXPECT_THROW(rate_pair(with([](auto& s) { s.grades = 0; }), a, a, rng), Error);
  EXPECT_THROW(rate_pair(SimulatedRaterSettings{}, a, a, rng), Error);  // JND not set
}

}  // namespace
}  // namespace cohaptic
