#include "common/study/measures.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <type_traits>

#include "common/study/zero_phase_lowpass.h"
#include "common/util/error.h"
#include "common/util/percentile.h"
#include "common/util/not_a_number.h"

namespace cohaptic {
namespace {

std::vector<Stroke> contact_strokes(const ForceTrace& trace, const MeasureSettings& settings) {
  validate(settings);
  return find_strokes(trace, settings.contact_fraction * peak_force_n(trace));
}

double mean_of_finite(const std::vector<double>& values) {
  double sum = 0;
  std::size_t n = 0;
  for (double v : values)
    if (std::isfinite(v)) {
      sum += v;
      ++n;
    }
  return n > 0 ? sum / static_cast<double>(n) : kNaN;
}

// Index of the first deepest sample of the stroke (relative to stroke.begin).
std::size_t deepest(const std::vector<double>& s) {
  return static_cast<std::size_t>(std::max_element(s.begin(), s.end()) - s.begin());
}

}  // namespace

void validate(const MeasureSettings& s) {
  if (!(s.contact_fraction > 0 && s.contact_fraction < 1))
    throw Error(fmt::format("contact fraction must be in (0, 1), got {}", s.contact_fraction));
  if (!(s.lowpass_hz > 0) || !std::isfinite(s.lowpass_hz))
    throw Error(
        fmt::format("low-pass cut-off must be a positive frequency, got {} Hz", s.lowpass_hz));
  if (!(s.min_stroke_s >= 0) || !std::isfinite(s.min_stroke_s))
    throw Error(fmt::format("minimum stroke duration must be >= 0 s, got {}", s.min_stroke_s));
  if (s.oscillation_reversals < 2)
    throw Error(
        fmt::format("an oscillation needs at least 2 reversals, got {}", s.oscillation_reversals));
  if (!(s.oscillation_window_s > 0) || !std::isfinite(s.oscillation_window_s))
    throw Error(fmt::format("oscillation window must be > 0 s, got {}", s.oscillation_window_s));
  if (!(s.oscillation_swing_fraction > 0 && s.oscillation_swing_fraction <= 1))
    throw Error(fmt::format("oscillation swing must be in (0, 1] of the peak, got {}",
                            s.oscillation_swing_fraction));
}

double force_update_rate_hz(const ForceTrace& trace, const MeasureSettings& settings) {
  double contact_s = 0;
  std::size_t changes = 0;
  for (const Stroke& stroke : contact_strokes(trace, settings)) {
    contact_s += duration_s(trace, stroke);
    for (std::size_t k = stroke.begin + 1; k < stroke.end; ++k)
      if (trace.force[k] != trace.force[k - 1]) ++changes;
  }
  return contact_s > 0 ? static_cast<double>(changes) / contact_s : kNaN;
}

double p99_force_step_ratio(const ForceTrace& trace, const MeasureSettings& settings) {
  std::vector<double> steps;
  for (const Stroke& stroke : contact_strokes(trace, settings))
    for (std::size_t k = stroke.begin + 1; k < stroke.end; ++k)
      steps.push_back((trace.force[k] - trace.force[k - 1]).norm());
  const double peak = peak_force_n(trace);
  return steps.empty() || !(peak > 0) ? kNaN : percentile(std::move(steps), 0.99) / peak;
}

double roughness(const ForceTrace& trace, const MeasureSettings& settings) {
  const std::vector<Stroke> strokes = contact_strokes(trace, settings);
  if (strokes.empty()) return kNaN;
  const std::vector<Eigen::Vector3d> smooth =
      zero_phase_lowpass(trace.time_s, trace.force, settings.lowpass_hz);
  double sum_sq = 0;
  std::size_t n = 0;
  for (const Stroke& stroke : strokes)
    for (std::size_t k = stroke.begin; k < stroke.end; ++k) {
      sum_sq += (trace.force[k] - smooth[k]).squaredNorm();
      ++n;
    }
  return std::sqrt(sum_sq / static_cast<double>(n)) / peak_force_n(trace);
}

Eigen::Vector3d press_direction(const ForceTrace& trace, const Stroke& stroke) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (std::size_t k = stroke.begin; k < stroke.end; ++k) sum += trace.force[k];
  const double norm = sum.norm();
  return norm > 0 ? Eigen::Vector3d(-sum / norm) : Eigen::Vector3d::Zero();
}

std::vector<double> displacement_m(const ForceTrace& trace, const Stroke& stroke) {
  if (stroke.begin > stroke.end || stroke.end > trace.size())
    throw Error(fmt::format("stroke [{}, {}) is outside the trace of {} samples", stroke.begin,
                            stroke.end, trace.size()));
  const Eigen::Vector3d d = press_direction(trace, stroke);
  std::vector<double> s;
  s.reserve(stroke.size());
  for (std::size_t k = stroke.begin; k < stroke.end; ++k)
    s.push_back((trace.position[k] - trace.position[stroke.begin]).dot(d));
  return s;
}

double terminal_force_ratio(const ForceTrace& trace, const Stroke& stroke) {
  const std::vector<double> s = displacement_m(trace, stroke);
  if (s.empty()) return kNaN;
  double peak = 0;
  for (std::size_t k = stroke.begin; k < stroke.end; ++k)
    peak = std::max(peak, trace.force[k].norm());
  return peak > 0 ? trace.force[stroke.begin + deepest(s)].norm() / peak : kNaN;
}

double effective_stiffness(const ForceTrace& trace, const Stroke& stroke) {
  const std::vector<double> s = displacement_m(trace, stroke);
  if (s.size() < 2) return kNaN;
  const std::size_t m = deepest(s) + 1;  // loading phase: samples 0..k*
  double mean_s = 0, mean_f = 0;
  for (std::size_t j = 0; j < m; ++j) {
    mean_s += s[j];
    mean_f += trace.force[stroke.begin + j].norm();
  }
  mean_s /= static_cast<double>(m);
  mean_f /= static_cast<double>(m);
  double sxx = 0, sxy = 0;
  for (std::size_t j = 0; j < m; ++j) {
    const double ds = s[j] - mean_s;
    sxx += ds * ds;
    sxy += ds * (trace.force[stroke.begin + j].norm() - mean_f);
  }
  return sxx > 0 ? sxy / sxx : kNaN;
}

double hysteresis_energy(const ForceTrace& trace, const Stroke& stroke) {
  if (stroke.begin > stroke.end || stroke.end > trace.size())
    throw Error(fmt::format("stroke [{}, {}) is outside the trace of {} samples", stroke.begin,
                            stroke.end, trace.size()));
  if (stroke.size() < 2) return kNaN;
  double work = 0;
  for (std::size_t k = stroke.begin; k + 1 < stroke.end; ++k)
    work -=
        0.5 * (trace.force[k] + trace.force[k + 1]).dot(trace.position[k + 1] - trace.position[k]);
  return work;
}

double energy_given_to_hand(const ForceTrace& trace) {
  validate(trace);
  double work = 0;
  for (std::size_t k = 0; k + 1 < trace.size(); ++k)
    work += trace.force[k].dot(trace.position[k + 1] - trace.position[k]);
  return work;
}

std::vector<OscillationEpisode> find_oscillations(const ForceTrace& trace,
                                                  const MeasureSettings& settings) {
  validate(trace);
  validate(settings);
  const double peak = peak_force_n(trace);
  if (!(peak > 0)) return {};
  Eigen::Vector3d axis = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& f : trace.force) axis += f;
  if (axis.norm() > 1e-12 * peak) {
    axis.normalize();
  } else {  // forces cancel out: take the direction of the peak
    const auto it = std::max_element(
        trace.force.begin(), trace.force.end(),
        [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return a.norm() < b.norm(); });
    axis = it->normalized();
  }
  const double swing = settings.oscillation_swing_fraction * peak;

  // Turning points of f = F . axis with hysteresis `swing` (a zig-zag filter).
  std::vector<double> reversal_s;
  int direction = 0;  // +1 rising, -1 falling, 0 not yet known
  double hi = trace.force[0].dot(axis), lo = hi, extreme = hi;
  std::size_t hi_k = 0, lo_k = 0, extreme_k = 0;
  for (std::size_t k = 1; k < trace.size(); ++k) {
    const double f = trace.force[k].dot(axis);
    if (direction == 0) {
      if (f > hi) {
        hi = f;
        hi_k = k;
      }
      if (f < lo) {
        lo = f;
        lo_k = k;
      }
      if (hi - lo >= swing) {
        direction = hi_k > lo_k ? +1 : -1;
        extreme = direction > 0 ? hi : lo;
        extreme_k = direction > 0 ? hi_k : lo_k;
      }
    } else if (direction * (f - extreme) > 0) {
      extreme = f;
      extreme_k = k;
    } else if (direction * (extreme - f) >= swing) {
      reversal_s.push_back(trace.time_s[extreme_k]);
      direction = -direction;
      extreme = f;
      extreme_k = k;
    }
  }

  // Windows of N consecutive reversals within the window length; overlapping ones merge.
  std::vector<OscillationEpisode> episodes;
  const auto n = static_cast<std::size_t>(settings.oscillation_reversals);
  std::size_t last_covered = 0;
  bool open = false;
  for (std::size_t i = 0; i + n <= reversal_s.size(); ++i) {
    const std::size_t j = i + n - 1;
    if (reversal_s[j] - reversal_s[i] > settings.oscillation_window_s) continue;
    if (!open || i > last_covered) {
      episodes.push_back({reversal_s[i], reversal_s[j], static_cast<int>(n)});
      open = true;
    } else {
      episodes.back().end_s = reversal_s[j];
      episodes.back().reversals += static_cast<int>(j - last_covered);
    }
    last_covered = j;
  }
  return episodes;
}

int oscillation_episodes(const ForceTrace& trace, const MeasureSettings& settings) {
  return static_cast<int>(find_oscillations(trace, settings).size());
}

TrialMeasures measure_trial(const ForceTrace& trace, const MeasureSettings& settings) {
  const std::vector<Stroke> strokes = contact_strokes(trace, settings);
  TrialMeasures m;
  m.duration_s = trace.size() > 0 ? trace.time_s.back() - trace.time_s.front() : 0;
  for (const Stroke& stroke : strokes) m.contact_time_s += duration_s(trace, stroke);
  m.peak_force_n = peak_force_n(trace);
  m.force_update_rate_hz = force_update_rate_hz(trace, settings);
  m.p99_force_step_ratio = p99_force_step_ratio(trace, settings);
  m.roughness = roughness(trace, settings);

  std::vector<double> terminal, stiffness, hysteresis;
  for (const Stroke& stroke : strokes) {
    if (duration_s(trace, stroke) < settings.min_stroke_s) continue;
    terminal.push_back(terminal_force_ratio(trace, stroke));
    stiffness.push_back(effective_stiffness(trace, stroke));
    hysteresis.push_back(hysteresis_energy(trace, stroke));
  }
  m.n_strokes = terminal.size();
  m.terminal_force_ratio = mean_of_finite(terminal);
  m.effective_stiffness_n_per_m = mean_of_finite(stiffness);
  m.hysteresis_energy_j = mean_of_finite(hysteresis);

  m.energy_given_to_hand_j = energy_given_to_hand(trace);
  m.oscillation_episodes = oscillation_episodes(trace, settings);
  return m;
}

namespace {

// Every field of TrialMeasures with its name, in declaration order: the one list both
// directions (to names, from names) read.
template <typename Measures, typename Visit>
void for_each_measure(Measures& m, Visit&& visit) {
  visit("duration_s", m.duration_s);
  visit("contact_time_s", m.contact_time_s);
  visit("peak_force_n", m.peak_force_n);
  visit("force_update_rate_hz", m.force_update_rate_hz);
  visit("p99_force_step_ratio", m.p99_force_step_ratio);
  visit("roughness", m.roughness);
  visit("n_strokes", m.n_strokes);
  visit("terminal_force_ratio", m.terminal_force_ratio);
  visit("effective_stiffness_n_per_m", m.effective_stiffness_n_per_m);
  visit("hysteresis_energy_j", m.hysteresis_energy_j);
  visit("energy_given_to_hand_j", m.energy_given_to_hand_j);
  visit("oscillation_episodes", m.oscillation_episodes);
}

}  // namespace

std::vector<NamedMeasure> named_measures(const TrialMeasures& m) {
  std::vector<NamedMeasure> named;
  for_each_measure(m, [&](std::string_view name, const auto& value) {
    named.push_back({name, static_cast<double>(value)});
  });
  return named;
}

TrialMeasures trial_measures_from(const std::function<double(std::string_view)>& value_of) {
  TrialMeasures m;
  for_each_measure(m, [&](std::string_view name, auto& value) {
    value = static_cast<std::remove_reference_t<decltype(value)>>(value_of(name));
  });
  return m;
}

}  // namespace cohaptic
