// Zero-phase low-pass of a sampled vector signal: a 2nd-order Butterworth run forwards and then
// backwards (like scipy.signal.filtfilt), used by roughness() to split a force into its smooth
// part and its steps.
//
// Units: time [s], cut-off [Hz]; the signal keeps its own unit. The sample rate is taken as
// 1 / median(sample interval), so the signal should be sampled nearly uniformly (a haptic loop).
// The Butterworth section comes from the bilinear transform with pre-warping, so its -3 dB point
// is exactly cutoff_hz; run twice it is -6 dB there, with magnitude 1 / (1 + (f / fc)^4) and no
// phase shift at all. Both ends are padded by odd reflection (2 x(0) - x(j), j = 1..pad, with
// pad = min(n - 1, 15 time constants of the filter)), and each pass starts from the steady state
// of its first padded value, so a constant or a straight line comes out unchanged up to rounding
// (end transients decay inside the padding), and so does any straight segment far (> ~80 ms at
// 20 Hz) from a corner. Invariants: output length = input length; a trace of < 2 samples is
// returned unchanged. Throws Error if cutoff_hz is not positive or not below the Nyquist rate.
#pragma once

#include <Eigen/Core>

#include <vector>

namespace cohaptic {

std::vector<Eigen::Vector3d> zero_phase_lowpass(const std::vector<double>& time_s,
                                                const std::vector<Eigen::Vector3d>& signal,
                                                double cutoff_hz);

}  // namespace cohaptic
