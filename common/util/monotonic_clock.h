// The session's one clock: std::chrono::steady_clock, in nanoseconds. Every message header
// carries it (Header.sender_time_ns), the clock-offset filter compares it between hosts, and
// the loops, delays and reports time themselves by it. On Linux steady_clock is
// CLOCK_MONOTONIC, so a thread can sleep until one of its times with clock_nanosleep.
#pragma once

#include <chrono>
#include <cstdint>

namespace cohaptic {

/// Nanoseconds of std::chrono::steady_clock now.
inline std::int64_t monotonic_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace cohaptic
