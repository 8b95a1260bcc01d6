#include "common/study/zero_phase_lowpass.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "common/util/error.h"

namespace cohaptic {
namespace {

struct Biquad {
  double b0, b1, b2, a1, a2;  // y = b0 x + b1 x1 + b2 x2 - a1 y1 - a2 y2
};

Biquad butterworth_lowpass(double cutoff_hz, double rate_hz) {
  const double k = std::tan(std::numbers::pi * cutoff_hz / rate_hz);
  const double norm = 1 / (1 + std::numbers::sqrt2 * k + k * k);
  const double b0 = k * k * norm;
  return {b0, 2 * b0, b0, 2 * (k * k - 1) * norm, (1 - std::numbers::sqrt2 * k + k * k) * norm};
}

// Direct form I, starting from the steady state of x[0] (unit DC gain: past inputs and outputs =
// x[0]).
void run(const Biquad& q, std::vector<Eigen::Vector3d>& x) {
  if (x.empty()) return;
  Eigen::Vector3d x1 = x[0], x2 = x[0], y1 = x[0], y2 = x[0];
  for (Eigen::Vector3d& v : x) {
    const Eigen::Vector3d y = q.b0 * v + q.b1 * x1 + q.b2 * x2 - q.a1 * y1 - q.a2 * y2;
    x2 = x1;
    x1 = v;
    y2 = y1;
    y1 = y;
    v = y;
  }
}

}  // namespace

std::vector<Eigen::Vector3d> zero_phase_lowpass(const std::vector<double>& time_s,
                                                const std::vector<Eigen::Vector3d>& signal,
                                                double cutoff_hz) {
  if (time_s.size() != signal.size())
    throw Error(fmt::format("low-pass: {} times for {} samples", time_s.size(), signal.size()));
  if (!(cutoff_hz > 0) || !std::isfinite(cutoff_hz))
    throw Error(fmt::format("low-pass cut-off must be a positive frequency, got {} Hz", cutoff_hz));
  const std::size_t n = signal.size();
  if (n < 2) return signal;

  std::vector<double> dt(n - 1);
  for (std::size_t k = 0; k + 1 < n; ++k) dt[k] = time_s[k + 1] - time_s[k];
  std::nth_element(dt.begin(), dt.begin() + static_cast<std::ptrdiff_t>(dt.size() / 2), dt.end());
  const double median_dt = dt[dt.size() / 2];
  if (!(median_dt > 0)) throw Error("low-pass: sample times must strictly increase");
  const double rate_hz = 1 / median_dt;
  if (!(cutoff_hz < rate_hz / 2))
    throw Error(fmt::format("low-pass cut-off {} Hz must be below half the sample rate ({} Hz)",
                            cutoff_hz, rate_hz));

  // The slowest pole of a 2nd-order Butterworth decays at rate 2 pi fc / sqrt(2).
  const double time_constant_s = std::numbers::sqrt2 / (2 * std::numbers::pi * cutoff_hz);
  const auto wanted = static_cast<std::size_t>(std::ceil(15 * time_constant_s * rate_hz));
  const std::size_t pad = std::min(n - 1, std::max<std::size_t>(wanted, 1));

  std::vector<Eigen::Vector3d> x;
  x.reserve(n + 2 * pad);
  for (std::size_t j = pad; j >= 1; --j) x.push_back(2 * signal[0] - signal[j]);
  x.insert(x.end(), signal.begin(), signal.end());
  for (std::size_t j = 1; j <= pad; ++j) x.push_back(2 * signal[n - 1] - signal[n - 1 - j]);

  const Biquad q = butterworth_lowpass(cutoff_hz, rate_hz);
  run(q, x);
  std::reverse(x.begin(), x.end());
  run(q, x);
  std::reverse(x.begin(), x.end());
  return {x.begin() + static_cast<std::ptrdiff_t>(pad),
          x.begin() + static_cast<std::ptrdiff_t>(pad + n)};
}

}  // namespace cohaptic
