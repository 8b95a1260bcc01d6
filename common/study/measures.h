// Objective measures of one haptic client's force trace, standing in for the paper's subjective
// ratings: fineness of the force (Fig. 4: stepwise vs smooth under step delay), hardness of a
// press (Fig. 1: under shift delay the force at the deepest point is below the maximum), and
// stability (energy the device injects, force oscillations).
//
// Notation: sample k at time t(k) [s] has force F(k) [N] (on the hand, ForceTrace) and tool
// position x(k) [m]; P = max_k |F(k)| is the trace's peak force; "contact" = the samples of the
// strokes of find_strokes() with threshold settings.contact_fraction x P (default 1 %). A
// measure that has nothing to measure (no contact, no stroke long enough, ...) is NaN, never an
// exception; only malformed traces or settings throw Error. The definitions:
//
// Fineness (over all contact samples of the trace):
//   force_update_rate_hz  = C / T, where C = number of k with k-1 and k in the same stroke and
//                           F(k) != F(k-1) (bitwise: a held value does not count), and
//                           T = sum over strokes of t(end-1) - t(begin) [Hz]. A force recomputed
//                           every sample scores the sample rate; one held for 25 ms scores 40 Hz.
//   p99_force_step_ratio  = 99th percentile over the same pairs (k-1, k) of |F(k) - F(k-1)|,
//                           divided by P [1]. Percentile with linear interpolation between order
//                           statistics at rank 0.99 (m - 1), as numpy's default.
//   roughness             = sqrt(mean over contact samples of |F(k) - F_lp(k)|^2) / P [1], where
//                           F_lp is F through zero_phase_lowpass() at settings.lowpass_hz
//                           (20 Hz): a 2nd-order Butterworth run forwards and backwards over the
//                           whole trace. Zero phase, so a smooth ramp has roughness ~0 and only
//                           steps and fast wiggles remain.
//
// Hardness (per stroke S = [b, e); TrialMeasures holds the mean over strokes):
//   press direction       d = -normalise(sum_{k in S} F(k)): the mean force on the hand points
//                           out of the object, so d points into it.
//   displacement          s(k) = (x(k) - x(b)) . d [m]: penetration since the stroke began.
//                           k* = the first k in S with the greatest s(k) (deepest point).
//   terminal_force_ratio  = |F(k*)| / max_{k in S} |F(k)| [1]: 1 without delay for a monotone
//                           spring; cos(w tau) for a sinusoidal press x = A sin(w t) answered
//                           with a force shifted by tau.
//   effective_stiffness   = least-squares slope b1 of |F(k)| ~ b0 + b1 s(k) over the loading
//                           phase k = b..k* [N/m] (NaN if fewer than 2 distinct s).
//   hysteresis_energy     = -sum_{k=b}^{e-2} (F(k) + F(k+1))/2 . (x(k+1) - x(k)) [J]: the work
//                           the hand did against the force over the stroke (trapezoidal, so a
//                           pure spring over a closed path gives exactly 0) = loading work minus
//                           work given back while unloading. > 0 for a lossy (damped) loop;
//                           < 0 when the environment gave back more than it received, as a
//                           force delayed behind the motion does.
//
// Stability (over the whole trace):
//   energy_given_to_hand  = W = sum_{k=0}^{n-2} F(k) . (x(k+1) - x(k)) [J]: the work of the force
//                           held by the device during each sample interval on the moving hand.
//                           W > 0 means the virtual environment injected energy (non-passive).
//                           A sampled spring gives the small positive k/2 sum |dx|^2 (the
//                           zero-order hold's own energy leak); a damper gives W < 0.
//   oscillation_episodes  = number of episodes found by find_oscillations(): with the main
//                           axis a = normalise(sum_k F(k)) and f(k) = F(k) . a, a reversal is a
//                           turning point of f confirmed once f has moved back from it by at
//                           least delta = settings.oscillation_swing_fraction x P (5 %); its
//                           time is the extremum's. A window is a run of N =
//                           settings.oscillation_reversals (4) consecutive reversals spanning
//                           at most settings.oscillation_window_s (100 ms), i.e. a swing
//                           faster than ~15 Hz; windows sharing a reversal merge into one
//                           episode. A smooth press (one reversal) has 0 episodes.
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <functional>
#include <string_view>
#include <vector>

#include "common/study/force_trace.h"

namespace cohaptic {

struct MeasureSettings {
  double contact_fraction = kDefaultContactFraction;  ///< stroke threshold as a fraction of P
  double lowpass_hz = 20;                             ///< roughness low-pass cut-off [Hz]
  double min_stroke_s = 0.05;  ///< shorter strokes are left out of the trial's hardness means [s]
  int oscillation_reversals = 4;             ///< N
  double oscillation_window_s = 0.1;         ///< [s]
  double oscillation_swing_fraction = 0.05;  ///< delta / P
};

/// Throws Error naming the first bad setting.
void validate(const MeasureSettings& settings);

// Fineness.
double force_update_rate_hz(const ForceTrace& trace, const MeasureSettings& settings = {});
double p99_force_step_ratio(const ForceTrace& trace, const MeasureSettings& settings = {});
double roughness(const ForceTrace& trace, const MeasureSettings& settings = {});

// Hardness of one stroke of the trace.
Eigen::Vector3d press_direction(const ForceTrace& trace,
                                const Stroke& stroke);  ///< d; zero if no force
std::vector<double> displacement_m(const ForceTrace& trace, const Stroke& stroke);  ///< s(b..e-1)
double terminal_force_ratio(const ForceTrace& trace, const Stroke& stroke);
double effective_stiffness(const ForceTrace& trace, const Stroke& stroke);  ///< [N/m]
double hysteresis_energy(const ForceTrace& trace, const Stroke& stroke);    ///< [J]

// Stability.
double energy_given_to_hand(const ForceTrace& trace);  ///< [J]

struct OscillationEpisode {
  double begin_s = 0, end_s = 0;  ///< times of its first and last reversal
  int reversals = 0;
};
std::vector<OscillationEpisode> find_oscillations(const ForceTrace& trace,
                                                  const MeasureSettings& settings = {});
int oscillation_episodes(const ForceTrace& trace, const MeasureSettings& settings = {});

/// Every measure of one trial (one trace). Hardness values are means over the strokes that
/// last at least settings.min_stroke_s (NaN strokes skipped; NaN if none).
struct TrialMeasures {
  double duration_s = 0;      ///< t(n-1) - t(0)
  double contact_time_s = 0;  ///< T above
  double peak_force_n = 0;    ///< P
  double force_update_rate_hz = 0;
  double p99_force_step_ratio = 0;
  double roughness = 0;
  std::size_t n_strokes = 0;  ///< strokes used for the hardness means
  double terminal_force_ratio = 0;
  double effective_stiffness_n_per_m = 0;
  double hysteresis_energy_j = 0;
  double energy_given_to_hand_j = 0;
  int oscillation_episodes = 0;
};

TrialMeasures measure_trial(const ForceTrace& trace, const MeasureSettings& settings = {});

/// One measure by name, for tables: the names are the TrialMeasures field names.
struct NamedMeasure {
  std::string_view name;
  double value;
};
/// All fields of TrialMeasures in declaration order.
std::vector<NamedMeasure> named_measures(const TrialMeasures& measures);
/// The measures back from their names (a table's row): `value_of(name)` for every field.
TrialMeasures trial_measures_from(const std::function<double(std::string_view)>& value_of);

}  // namespace cohaptic
