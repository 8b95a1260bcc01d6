// LoopStatistics: the simulation loop's figures for the status line and the report:
// step durations, M~ build times, IRs and forces sent, |B|, surface displacement, failed
// steps. The simulation thread (and the IR encoder's) records; the I/O thread (status line) and the
// main thread (report) read a summary. A mutex guards them (held for a few additions per step).
// Units: the histograms record ns; the summary gives ms, s and m.
#pragma once

#include <cstdint>
#include <mutex>
#include <string>

#include "common/sim/simulation.h"
#include "common/util/histogram.h"

namespace cohaptic {

/// What one successful step adds.
struct StepFigures {
  std::int64_t duration_ns = 0;
  StepReport report;
  std::uint64_t forces_sent = 0;  ///< P0 forces put in the outbox
};

/// The figures so far.
struct LoopSummary {
  std::uint64_t steps = 0, rebuilds = 0, ir_bytes = 0, irs_sent = 0, ir_bytes_sent = 0,
                forces_sent = 0;
  std::uint64_t irs_superseded = 0;  ///< built, replaced by a newer one before they were sent
  double step_p50_ms = 0, step_p99_ms = 0, step_max_ms = 0;
  double ir_build_p50_ms = 0, ir_build_p99_ms = 0;
  std::uint64_t ir_builds = 0;  ///< steps that computed M~
  double ir_encode_p50_ms = 0,
         ir_encode_p99_ms = 0;  ///< per batch of IRs: convert, compress, record
  int max_boundary_nodes = 0, max_obstacle_nodes = 0;
  /// Sphere model: over all steps, nodes the state had a sphere push that no IR's patch held
  std::uint64_t sphere_nodes_outside_patches = 0;
  double max_surface_displacement_m = 0;      ///< in the display frames
  bool separates = false;                     ///< the scene has a separation body
  double fractured_m2 = 0, vaporised_m2 = 0;  ///< separated so far, as of the latest step
  bool groove_record_full = false;
  std::uint64_t failed_steps = 0;
  int max_consecutive_failures = 0;
  std::string last_failure;
  double elapsed_s = 0;  ///< from the server's start to the end of the last step
  double first_step_s =
      0;  ///< from the server's start to the start of the first step (the scene loaded)
  /// Steps per second since the first step: the loading of the scene is no part of it.
  double rate_hz() const {
    return elapsed_s > first_step_s ? static_cast<double>(steps) / (elapsed_s - first_step_s) : 0.0;
  }
};

class LoopStatistics {
 public:
  void record_step(const StepFigures& step, double elapsed_s);
  /// IRs encoded (ir_encoder.h) in `encode_ns`: those handed over to be sent, their bytes as
  /// they travel (compliance rows, a stream block or M~ whole), and those superseded.
  void record_irs_encoded(std::int64_t encode_ns, std::uint64_t irs_sent, std::uint64_t bytes_sent,
                          std::uint64_t superseded);
  void record_failure(int consecutive, const std::string& what, double elapsed_s);
  void record_display_frame(double max_displacement_m);
  LoopSummary summary() const;

 private:
  mutable std::mutex mutex_;
  Histogram step_ns_{10'000, 100'000};       // 10 us bins up to 1 s
  Histogram ir_build_ns_{10'000, 100'000};   // steps that computed M~
  Histogram ir_encode_ns_{10'000, 100'000};  // steps' IRs encoded
  LoopSummary totals_;  // the counts and maxima (quantiles filled in by summary())
};

}  // namespace cohaptic
