// The study's measures (common/study) against answers computed by hand: step trains and ramps
// for fineness, a shift-delayed sinusoidal press and known loops for hardness, springs and
// (negative) dampers for the energy, and hand-computed statistics for the summary.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <iterator>
#include <numbers>
#include <sstream>

#include "common/study/force_trace.h"
#include "common/study/measures.h"
#include "common/study/summary.h"
#include "common/study/zero_phase_lowpass.h"
#include "common/util/error.h"
#include "common/util/not_a_number.h"
#include "support/process.h"

namespace cohaptic {
namespace {

constexpr double kPi = std::numbers::pi;

// Samples k = 0..n-1 at t = k dt of a force magnitude along `axis` and a position.
ForceTrace sample(std::size_t n, double dt,
                  const std::function<Eigen::Vector3d(std::size_t, double)>& force,
                  const std::function<Eigen::Vector3d(std::size_t, double)>& position) {
  ForceTrace trace;
  for (std::size_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) * dt;
    trace.time_s.push_back(t);
    trace.force.push_back(force(k, t));
    trace.position.push_back(position(k, t));
  }
  return trace;
}

const Eigen::Vector3d kAxis =
    Eigen::Vector3d(1, 2, 2) / 3;  // a unit vector off the coordinate axes
Eigen::Vector3d still(std::size_t, double) { return Eigen::Vector3d::Zero(); }

// 1 s at 1 kHz of 2 + 3 sin(pi t) N, recomputed every sample (smooth) or every 25 ms (steps).
ForceTrace press(std::size_t hold_samples) {
  return sample(
      1000, 1e-3,
      [&](std::size_t k, double) {
        const double held_t = static_cast<double>(k / hold_samples * hold_samples) * 1e-3;
        return Eigen::Vector3d((2 + 3 * std::sin(kPi * held_t)) * kAxis);
      },
      still);
}

// 1 s at 1 kHz of a ramp 1 + 4 t N, recomputed every sample or held for hold_samples.
ForceTrace ramp(std::size_t hold_samples) {
  return sample(
      1001, 1e-3,
      [&](std::size_t k, double) {
        const double held_t = static_cast<double>(k / hold_samples * hold_samples) * 1e-3;
        return Eigen::Vector3d((1 + 4 * held_t) * kAxis);
      },
      still);
}

TEST(MeasureTrace, StrokesAreTheRunsAboveTheThreshold) {
  ForceTrace trace;
  const double magnitudes[] = {0, 1, 2, 0, 0.005, 3, 3};
  for (std::size_t k = 0; k < std::size(magnitudes); ++k) {
    trace.time_s.push_back(0.1 * static_cast<double>(k));
    trace.force.push_back(magnitudes[k] * kAxis);
    trace.position.push_back(Eigen::Vector3d::Zero());
  }
  EXPECT_DOUBLE_EQ(peak_force_n(trace), 3);
  const std::vector<Stroke> strokes = find_strokes(trace);  // threshold 0.03 N
  ASSERT_EQ(strokes.size(), 2u);
  EXPECT_EQ(strokes[0].begin, 1u);
  EXPECT_EQ(strokes[0].end, 3u);
  EXPECT_EQ(strokes[1].begin, 5u);
  EXPECT_EQ(strokes[1].end, 7u);
  EXPECT_NEAR(duration_s(trace, strokes[1]), 0.1, 1e-12);
  EXPECT_EQ(find_strokes(trace, 0.001).size(), 2u);  // now 0.005 N starts the second stroke
  EXPECT_EQ(find_strokes(trace, 0.001)[1].begin, 4u);
  EXPECT_EQ(find_strokes(trace, 1.5).size(), 2u);
  EXPECT_TRUE(find_strokes(trace, 3).empty());
  EXPECT_THROW(find_strokes(trace, -1), Error);

  ForceTrace bad = trace;
  bad.position.pop_back();
  EXPECT_THROW(validate(bad), Error);
  bad = trace;
  bad.time_s[3] = bad.time_s[2];
  EXPECT_THROW(find_strokes(bad), Error);
  bad = trace;
  bad.force[2].x() = kNaN;
  EXPECT_THROW(validate(bad), Error);
  EXPECT_TRUE(find_strokes(ForceTrace{}).empty());
}

TEST(MeasureTrace, AForceThatFadesToZeroBrieflyWithinAPressIsOneStroke) {
  // 1 kHz: a press from 0.1 s to 0.9 s whose force fades to zero from 0.40 s to 0.52 s (a
  // stalled server), then a second press from 1.1 s, after a release of 0.2 s.
  const ForceTrace trace = sample(
      1400, 1e-3,
      [](std::size_t k, double) {
        const bool pressing = (k >= 100 && k < 900) || k >= 1100;
        const bool faded = k >= 400 && k < 520;
        return Eigen::Vector3d((pressing && !faded ? 1.0 : 0.0) * kAxis);
      },
      still);
  const std::vector<Stroke> strokes = find_strokes(trace);
  ASSERT_EQ(strokes.size(), 2u);
  EXPECT_EQ(strokes[0].begin, 100u);
  EXPECT_EQ(strokes[0].end, 900u);  // the dip inside
  EXPECT_EQ(strokes[1].begin, 1100u);
  EXPECT_EQ(measure_trial(trace).n_strokes, 2u);
}

TEST(MeasureLowpass, KeepsLinesAndConstantsAndFiltersAtTwentyHertz) {
  const auto signal = [](double hz) {
    return sample(
        2001, 1e-3,
        [hz](std::size_t, double t) {
          return Eigen::Vector3d(std::sin(2 * kPi * hz * t), 3, 2 + 5 * t);
        },
        still);
  };
  for (double hz : {5.0, 20.0, 100.0}) {
    const ForceTrace trace = signal(hz);
    const std::vector<Eigen::Vector3d> out = zero_phase_lowpass(trace.time_s, trace.force, 20);
    ASSERT_EQ(out.size(), trace.size());
    double amplitude = 0, line_error = 0;
    for (std::size_t k = 0; k < out.size(); ++k) {
      line_error =
          std::max(line_error, (out[k].tail<2>() - trace.force[k].tail<2>()).cwiseAbs().maxCoeff());
      if (k >= 500 && k <= 1500) amplitude = std::max(amplitude, std::abs(out[k].x()));
    }
    EXPECT_LT(line_error, 1e-6) << hz << " Hz";  // constant and straight line pass unchanged
    // Forward-backward 2nd-order Butterworth: gain 1 / (1 + (f / 20 Hz)^4).
    EXPECT_NEAR(amplitude, 1 / (1 + std::pow(hz / 20, 4)), 3e-3) << hz << " Hz";
  }
  const ForceTrace trace = signal(5);
  EXPECT_THROW(zero_phase_lowpass(trace.time_s, trace.force, 600), Error);  // above Nyquist
  EXPECT_THROW(zero_phase_lowpass(trace.time_s, trace.force, 0), Error);
}

TEST(MeasureFineness, StepTrainAtFortyHertzUpdatesAtFortyHertzWithLargeSteps) {
  const ForceTrace steps = press(25);  // a new value every 25 ms
  EXPECT_NEAR(force_update_rate_hz(steps), 40, 1);
  // Steps up to 3 pi 0.025 = 0.236 N against a 5 N peak.
  EXPECT_GT(p99_force_step_ratio(steps), 0.03);
  EXPECT_LT(p99_force_step_ratio(steps), 0.05);
  const ForceTrace smooth = press(1);
  EXPECT_NEAR(force_update_rate_hz(smooth), 1000, 1);
  EXPECT_LT(p99_force_step_ratio(smooth), 0.002);  // 3 pi 0.001 / 5 = 0.0019
}

TEST(MeasureFineness, SmoothRampUpdatesEverySampleAndHasNoRoughness) {
  const ForceTrace smooth = ramp(1);
  EXPECT_NEAR(force_update_rate_hz(smooth), 1000, 1e-6);  // 1000 changes in 1.000 s
  EXPECT_NEAR(p99_force_step_ratio(smooth), 0.004 / 5, 1e-9);
  EXPECT_LT(roughness(smooth), 1e-5);
}

TEST(MeasureFineness, StepwiseRampIsClearlyRougherThanTheSmoothOne) {
  const double smooth = roughness(ramp(1)), stepwise = roughness(ramp(25));
  // Steps of 0.1 N = 2 % of the peak: a sawtooth of RMS ~0.02 / sqrt(12) = 0.0058 remains.
  EXPECT_GT(stepwise, 0.003);
  EXPECT_LT(stepwise, 0.01);
  EXPECT_GT(stepwise, 100 * smooth);
  EXPECT_NEAR(force_update_rate_hz(ramp(25)), 40, 1);
}

TEST(MeasureFineness, NoContactGivesNaN) {
  const ForceTrace empty = sample(100, 1e-3, still, still);
  EXPECT_TRUE(std::isnan(force_update_rate_hz(empty)));
  EXPECT_TRUE(std::isnan(p99_force_step_ratio(empty)));
  EXPECT_TRUE(std::isnan(roughness(empty)));
  const TrialMeasures m = measure_trial(empty);
  EXPECT_EQ(m.n_strokes, 0u);
  EXPECT_TRUE(std::isnan(m.terminal_force_ratio));
  EXPECT_EQ(m.energy_given_to_hand_j, 0);
  EXPECT_EQ(m.oscillation_episodes, 0);
}

// One press x(t) = A sin(w t) into the object (along -z) for half a period of 0.5 s, answered by
// a spring force k A sin(w (t - tau)) (pushing along +z) shifted by tau, sampled at 1 kHz until
// the delayed force has ended. The tool rests at the surface after the press.
constexpr double kA = 0.01, kK = 500, kOmega = 2 * kPi;
ForceTrace delayed_press(double tau, double start_s = 0, std::size_t n = 0) {
  if (n == 0) n = static_cast<std::size_t>(std::lround((0.5 + tau) / 1e-3)) + 2;
  return sample(
      n, 1e-3,
      [=](std::size_t, double t) {
        const double u = t - start_s - tau;
        return Eigen::Vector3d(0, 0, u > 0 && u < 0.5 ? kK * kA * std::sin(kOmega * u) : 0);
      },
      [=](std::size_t, double t) {
        const double u = t - start_s;
        return Eigen::Vector3d(0, 0, u > 0 && u < 0.5 ? -kA * std::sin(kOmega * u) : 0);
      });
}

TEST(MeasureHardness, TerminalForceRatioOfAShiftDelayedPressIsCosOmegaTau) {
  for (double tau : {0.0, 0.03, 0.1, 0.2}) {
    const ForceTrace trace = delayed_press(tau);
    const std::vector<Stroke> strokes = find_strokes(trace);
    ASSERT_EQ(strokes.size(), 1u) << tau;
    // Deepest at t = pi / (2 w) = 0.25 s, where F = k A sin(pi/2 - w tau) = k A cos(w tau);
    // the maximum k A comes at 0.25 s + tau, still inside the stroke.
    EXPECT_NEAR(terminal_force_ratio(trace, strokes[0]), std::cos(kOmega * tau), 1e-3) << tau;
    EXPECT_TRUE(press_direction(trace, strokes[0]).isApprox(Eigen::Vector3d(0, 0, -1)));
    // Work the hand did over the stroke: int k A sin(w (t - tau)) A w cos(w t) dt on [tau, pi/w]
    // = -k A^2 sin(w tau) (pi - w tau) / 2: a delayed force gives back more than it took.
    const double loop = -0.5 * kK * kA * kA * std::sin(kOmega * tau) * (kPi - kOmega * tau);
    EXPECT_NEAR(hysteresis_energy(trace, strokes[0]), loop, 1e-3 * kK * kA * kA) << tau;
    EXPECT_NEAR(energy_given_to_hand(trace), -loop, 0.02 * kK * kA * kA) << tau;
  }
}

TEST(MeasureHardness, EffectiveStiffnessOfASpringIsItsStiffnessOverTheLoadingPhaseOnly) {
  const double k = 800, depth = 0.02;
  const Eigen::Vector3d d = Eigen::Vector3d(0, -0.6, -0.8);  // press direction
  // Load along F = k s for 0.5 s, unload along the softer k s^2 / depth for 0.5 s.
  const auto s_of = [&](double t) { return t <= 0.5 ? depth * t / 0.5 : depth * (1 - t) / 0.5; };
  const ForceTrace trace = sample(
      1001, 1e-3,
      [&](std::size_t, double t) {
        const double s = s_of(t);
        return Eigen::Vector3d(-(t <= 0.5 ? k * s : k * s * s / depth) * d);
      },
      [&](std::size_t, double t) {
        return Eigen::Vector3d(Eigen::Vector3d(0.1, 0.2, 0.3) + s_of(t) * d);
      });
  const std::vector<Stroke> strokes = find_strokes(trace);
  ASSERT_EQ(strokes.size(), 1u);
  EXPECT_NEAR(effective_stiffness(trace, strokes[0]), k, 1e-9 * k);
  EXPECT_NEAR(terminal_force_ratio(trace, strokes[0]), 1, 1e-12);
  // Loading work k depth^2 / 2 minus unloading work k depth^2 / 3 (the loop is lossy).
  // (1 %: the stroke misses the work below the 1 % contact threshold at both ends.)
  EXPECT_NEAR(hysteresis_energy(trace, strokes[0]), k * depth * depth / 6,
              1e-2 * k * depth * depth / 6);
}

// A closed loop of one period T = 0.5 s around a pressed state: s = 2A + A sin(w t) along -z,
// force on the hand (k s + c ds/dt) along +z.
ForceTrace loop(double c) {
  const double a = 0.005, k = 500, w = 4 * kPi;
  return sample(
      501, 1e-3,
      [=](std::size_t, double t) {
        return Eigen::Vector3d(0, 0,
                               k * (2 * a + a * std::sin(w * t)) + c * a * w * std::cos(w * t));
      },
      [=](std::size_t, double t) { return Eigen::Vector3d(0, 0, -(2 * a + a * std::sin(w * t))); });
}

TEST(MeasureHardness, HysteresisEnergyOfADampedLoopIsTheEllipseArea) {
  const double a = 0.005, w = 4 * kPi, c = 5;
  const ForceTrace damped = loop(c);
  const std::vector<Stroke> strokes = find_strokes(damped);
  ASSERT_EQ(strokes.size(), 1u);
  EXPECT_EQ(strokes[0].size(), damped.size());
  const double area = kPi * c * w * a * a;
  EXPECT_NEAR(hysteresis_energy(damped, strokes[0]), area, 0.01 * area);
  const ForceTrace spring = loop(0);
  EXPECT_NEAR(hysteresis_energy(spring, find_strokes(spring)[0]), 0,
              1e-12);  // trapezoids telescope
}

TEST(MeasureStability, PassiveSpringLoopGivesOnlyTheZeroOrderHoldLeak) {
  const ForceTrace spring = loop(0);
  // sum F(k) dx(k) = -k sum s_k (s_k+1 - s_k) = k/2 sum (s_k+1 - s_k)^2 on a closed loop.
  double hold_leak = 0;
  for (std::size_t k = 0; k + 1 < spring.size(); ++k)
    hold_leak += 0.5 * 500 * (spring.position[k + 1] - spring.position[k]).squaredNorm();
  const double w = energy_given_to_hand(spring);
  EXPECT_GE(w, 0);
  EXPECT_NEAR(w, hold_leak, 1e-9 * hold_leak + 1e-15);
  EXPECT_LT(w, 0.01 * 4 * 500 * 0.005 *
                   0.005);  // < 1 % of the work k (9 - 1) A^2 / 2 put in while loading
  // A real damper takes energy from the hand.
  EXPECT_LT(energy_given_to_hand(loop(5)), -0.9 * kPi * 5 * 4 * kPi * 0.005 * 0.005);
}

TEST(MeasureStability, NegativeDampingGivesTheHandItsWork) {
  // F = +c v (the force leads the motion by a quarter period): W = c int v^2 dt = pi c w A^2.
  const double a = 0.01, w = 2 * kPi * 3, c = 2;
  const std::size_t n = 1001;  // one period of 1/3 s at 1/3 ms
  const double dt = (1.0 / 3) / static_cast<double>(n - 1);
  const ForceTrace trace = sample(
      n, dt,
      [=](std::size_t, double t) { return Eigen::Vector3d(c * a * w * std::cos(w * t) * kAxis); },
      [=](std::size_t, double t) { return Eigen::Vector3d(a * std::sin(w * t) * kAxis); });
  const double expected = kPi * c * w * a * a;
  EXPECT_NEAR(energy_given_to_hand(trace), expected, 0.01 * expected);
}

// A half-sine press of 1 s and 5 N along kAxis, plus decaying 30 Hz bursts starting at `bursts`.
ForceTrace press_with_bursts(const std::vector<double>& bursts, double burst_hz = 30) {
  return sample(
      1000, 1e-3,
      [=](std::size_t, double t) {
        double f = 5 * std::sin(kPi * t);
        for (double t0 : bursts)
          if (t >= t0) f += std::exp(-(t - t0) / 0.05) * std::sin(2 * kPi * burst_hz * (t - t0));
        return Eigen::Vector3d(f * kAxis);
      },
      still);
}

TEST(MeasureStability, DecayingThirtyHertzOscillationIsOneEpisodeAndASmoothPressNone) {
  EXPECT_EQ(oscillation_episodes(press_with_bursts({})), 0);
  const std::vector<OscillationEpisode> one = find_oscillations(press_with_bursts({0.3}));
  ASSERT_EQ(one.size(), 1u);
  EXPECT_GE(one[0].reversals, 4);
  EXPECT_GE(one[0].begin_s, 0.3);
  EXPECT_LT(one[0].end_s, 0.55);
  EXPECT_EQ(oscillation_episodes(press_with_bursts({0.2, 0.6})), 2);
  EXPECT_EQ(oscillation_episodes(press_with_bursts({0.3}, 5)), 0);  // a 5 Hz wobble is too slow
  // Stepwise forces (a zero-order hold) never reverse: no oscillation.
  EXPECT_EQ(oscillation_episodes(press(100)), 0);
}

TEST(MeasureTrial, HardnessIsTheMeanOverStrokesAndShortBlipsAreLeftOut) {
  // Two presses with delays 0.1 s (at 0 s) and 0 s (at 1 s), and a 10 ms blip at 1.8 s.
  const ForceTrace first = delayed_press(0.1, 0, 2000), second = delayed_press(0, 1, 2000);
  ForceTrace trace = first;
  for (std::size_t k = 0; k < trace.size(); ++k) {
    if (first.force[k].norm() == 0) trace.force[k] = second.force[k];
    if (first.position[k].norm() == 0) trace.position[k] = second.position[k];
    if (k >= 1800 && k < 1810) trace.force[k] = Eigen::Vector3d(0, 0, 2);
  }
  ASSERT_EQ(find_strokes(trace).size(), 3u);
  const TrialMeasures m = measure_trial(trace);
  EXPECT_EQ(m.n_strokes, 2u);
  EXPECT_NEAR(m.terminal_force_ratio, (std::cos(kOmega * 0.1) + 1) / 2, 1e-3);
  EXPECT_NEAR(m.peak_force_n, kK * kA, 1e-9);
  EXPECT_NEAR(m.duration_s, 1.999, 1e-12);
  EXPECT_NEAR(m.effective_stiffness_n_per_m,
              effective_stiffness(trace, find_strokes(trace)[1]) / 2 +
                  effective_stiffness(trace, find_strokes(trace)[0]) / 2,
              1e-9);
  EXPECT_GT(m.force_update_rate_hz, 980);  // the blip holds one value for 10 ms
  EXPECT_LT(m.force_update_rate_hz, 1000);
  const std::vector<NamedMeasure> named = named_measures(m);
  ASSERT_EQ(named.size(), 12u);
  EXPECT_EQ(named[0].name, "duration_s");
  EXPECT_EQ(named[7].name, "terminal_force_ratio");
  EXPECT_EQ(named[7].value, m.terminal_force_ratio);
  EXPECT_EQ(named.back().name, "oscillation_episodes");

  MeasureSettings bad;
  bad.lowpass_hz = -1;
  EXPECT_THROW(measure_trial(trace, bad), Error);
}

TEST(MeasureSummary, MeanSdAndNMatchAHandComputation) {
  const double values[] = {1, 2, 3, 4, kNaN};
  const Statistics s = describe(values);
  EXPECT_EQ(s.n, 4u);
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_NEAR(s.sd, std::sqrt(5.0 / 3), 1e-15);  // (2.25 + 0.25 + 0.25 + 2.25) / 3
  const double one[] = {7};
  EXPECT_TRUE(std::isnan(describe(one).sd));
  EXPECT_EQ(describe(std::span<const double>{}).n, 0u);

  const auto with_roughness = [](const char* condition, double roughness) {
    TrialMeasures measures;
    measures.roughness = roughness;
    return condition_trial(condition, measures);
  };
  std::vector<ConditionTrial> trials = {
      with_roughness("S30-T150-P0", 0.1), with_roughness("S0, \"fast\"", 0.5),
      with_roughness("S30-T150-P0", 0.3), with_roughness("S30-T150-P0", kNaN)};
  trials[1].values.push_back({"server_rate_hz", 400});  // a value only some trials have
  const std::vector<ConditionSummary> summary = summarize(trials);
  ASSERT_EQ(summary.size(), 2 * (named_measures(TrialMeasures{}).size() + 1));
  const auto find = [&](const std::string& condition, const std::string& measure) {
    for (const ConditionSummary& row : summary)
      if (row.condition == condition && row.measure == measure) return row;
    ADD_FAILURE() << condition << " " << measure;
    return ConditionSummary{};
  };
  EXPECT_EQ(summary.front().condition, "S30-T150-P0");  // order of first appearance
  const ConditionSummary a = find("S30-T150-P0", "roughness");
  EXPECT_EQ(a.n, 2u);
  EXPECT_NEAR(a.mean, 0.2, 1e-15);
  EXPECT_NEAR(a.sd, std::sqrt(0.02), 1e-12);
  const ConditionSummary b = find("S0, \"fast\"", "roughness");
  EXPECT_EQ(b.n, 1u);
  EXPECT_DOUBLE_EQ(b.mean, 0.5);
  EXPECT_TRUE(std::isnan(b.sd));
  EXPECT_EQ(find("S30-T150-P0", "n_strokes").n, 3u);
  EXPECT_EQ(find("S30-T150-P0", "server_rate_hz").n, 0u);
  EXPECT_DOUBLE_EQ(find("S0, \"fast\"", "server_rate_hz").mean, 400);
  EXPECT_EQ(summary.back().measure, "server_rate_hz");  // after the measures

  const std::filesystem::path path = testing::scratch_directory("summary") / "summary.csv";
  write_summary_csv(path, summary);
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str().substr(0, 28), "condition,measure,mean,sd,n\n");
  EXPECT_NE(text.str().find("\nS30-T150-P0,roughness,0.2,0.141421356,2\n"), std::string::npos)
      << text.str();
  EXPECT_NE(text.str().find("\n\"S0, \"\"fast\"\"\",roughness,0.5,nan,1\n"), std::string::npos)
      << text.str();
}

}  // namespace
}  // namespace cohaptic
