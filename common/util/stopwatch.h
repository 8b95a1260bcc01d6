// Stopwatch: elapsed wall time on the monotonic clock, in milliseconds.
#pragma once

#include <chrono>

namespace cohaptic {

class Stopwatch {
 public:
  Stopwatch() : start_(std::chrono::steady_clock::now()) {}
  double elapsed_ms() const {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_).count();
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

}  // namespace cohaptic
