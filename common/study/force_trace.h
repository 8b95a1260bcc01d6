// ForceTrace: what one haptic client recorded at its haptic rate, and its division into strokes.
//
// Sample k holds time_s[k] [s], force[k] [N] (the force output to the device, i.e. the force
// acting on the user's hand) and position[k] [m] (the tool position). Invariants checked by
// validate(): the three vectors have the same length, times strictly increase, all values are
// finite. The rate is nearly uniform (the haptic loop), but nothing here needs it exact except
// the low-pass filter of roughness() (measures.h), which uses the median sample interval.
//
// A stroke is one press of the hand: a maximal run of consecutive samples with |F(k)| >
// threshold (strictly above), stored as the half-open index range [begin, end), where two runs
// less than kMinReleaseS apart (from the last sample of one to the first of the next) are one
// stroke, the dip between them included. A hand cannot let go and press again that fast, but
// the force can dip that briefly while the hand presses on (a fade while the server is slow):
// that is one press, not two. The default threshold is 1 % of the trace's peak |F|, so a trace
// that never pushes (peak 0) has no stroke. Strokes are disjoint and ordered. "During contact"
// in the measures means "in some stroke".
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <vector>

namespace cohaptic {

struct ForceTrace {
  std::vector<double> time_s;
  std::vector<Eigen::Vector3d> force;     ///< [N] on the hand, as output to the device
  std::vector<Eigen::Vector3d> position;  ///< [m] tool position

  std::size_t size() const { return time_s.size(); }
};

/// Half-open sample range [begin, end) of one stroke.
struct Stroke {
  std::size_t begin = 0;
  std::size_t end = 0;

  std::size_t size() const { return end - begin; }
};

/// The contact threshold used when none is given: this fraction of the peak |F|.
inline constexpr double kDefaultContactFraction = 0.01;

/// Runs above the threshold closer than this are one stroke [s].
inline constexpr double kMinReleaseS = 0.15;

/// Throws Error naming the first broken invariant (lengths, order of times, finiteness).
void validate(const ForceTrace& trace);

/// max_k |F(k)| [N]; 0 for an empty trace.
double peak_force_n(const ForceTrace& trace);

/// Strokes with |F| > threshold_n [N]. Validates the trace; throws Error if threshold_n < 0 or NaN.
std::vector<Stroke> find_strokes(const ForceTrace& trace, double threshold_n);

/// Strokes with |F| > kDefaultContactFraction x peak |F|.
std::vector<Stroke> find_strokes(const ForceTrace& trace);

/// time_s[end - 1] - time_s[begin] [s]: 0 for a one-sample stroke.
double duration_s(const ForceTrace& trace, const Stroke& stroke);

}  // namespace cohaptic
