// Stopwatch: elapsed wall time on the monotonic clock, in milliseconds; and the calling
// thread's own CPU time, in microseconds (what a piece of work cost one thread, whatever
// else the machine ran).
#pragma once

#include <time.h>

#include <chrono>

namespace cohaptic {

class Stopwatch {
 public:
  Stopwatch() : start_(std::chrono::steady_clock::now()) {}
  double elapsed_ms() const {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_)
        .count();
  }
  /// Elapsed time, then restart.
  double lap_ms() {
    const double ms = elapsed_ms();
    start_ = std::chrono::steady_clock::now();
    return ms;
  }

 private:
  std::chrono::steady_clock::time_point start_;
};

/// CPU time the calling thread has used so far [µs] (CLOCK_THREAD_CPUTIME_ID).
inline double thread_cpu_us() {
  timespec now{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
  return static_cast<double>(now.tv_sec) * 1e6 + static_cast<double>(now.tv_nsec) * 1e-3;
}

}  // namespace cohaptic
