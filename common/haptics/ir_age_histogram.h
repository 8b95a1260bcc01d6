// The histogram of IR ages (P1: of the IR a haptic tick used; P0: of the server's force):
// 0.1 ms bins up to 2 s, the exact maximum kept. The haptic loop fills one live and `replay`
// another from a recording's ticks, so that both give the same p50/p99/max [ns].
#pragma once

#include "common/util/histogram.h"

namespace cohaptic {

inline Histogram ir_age_histogram() { return Histogram(100'000, 20'000); }

}  // namespace cohaptic
