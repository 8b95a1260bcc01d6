// FadeTally: the fades a user felt. A fade is a run of haptic ticks in which the force the
// user pushed against was faded out because what it came from (an IR, P1; the server's
// force, P0) was older than the fade age. The haptic loop counts them live, `replay` from a
// recording's ticks, by this one rule. Durations count each tick as `period_s` [s].
#pragma once

#include <algorithm>
#include <cstdint>

namespace cohaptic {

struct FadeTally {
  std::uint64_t count = 0;  ///< fades
  double total_s = 0;       ///< their durations, summed [s]
  double longest_s = 0;     ///< the longest one [s]

  /// One tick: `fade` its fade factor (1: none), `pushing` whether the unfaded force was
  /// non-zero. noexcept and allocation-free: the haptic loop calls it every tick.
  void tick(float fade, bool pushing, double period_s) noexcept {
    if (fade < 1 && pushing) {
      if (run_s_ == 0) ++count;
      run_s_ += period_s;
      total_s += period_s;
      longest_s = std::max(longest_s, run_s_);
    } else {
      run_s_ = 0;
    }
  }

 private:
  double run_s_ = 0;  // how long the current fade has lasted [s]
};

}  // namespace cohaptic
