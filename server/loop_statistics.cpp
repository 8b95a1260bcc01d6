#include "server/loop_statistics.h"

#include <algorithm>

namespace cohaptic {

void LoopStatistics::record_step(const StepFigures& step, double elapsed_s) {
  std::lock_guard lock(mutex_);
  if (totals_.steps == 0)
    totals_.first_step_s = elapsed_s - static_cast<double>(step.duration_ns) * 1e-9;
  step_ns_.record(step.duration_ns);
  if (step.report.recomputed)
    ir_build_ns_.record(static_cast<std::int64_t>(step.report.rebuild_ms * 1e6));
  if (step.report.rebuilt) {
    ++totals_.rebuilds;
    totals_.ir_bytes += step.report.ir_bytes;
  }
  ++totals_.steps;
  totals_.forces_sent += step.forces_sent;
  totals_.max_boundary_nodes = std::max(totals_.max_boundary_nodes, step.report.boundary_nodes);
  totals_.max_obstacle_nodes = std::max(totals_.max_obstacle_nodes, step.report.obstacle_nodes);
  totals_.sphere_nodes_outside_patches +=
      static_cast<std::uint64_t>(step.report.sphere_nodes_outside_patches);
  totals_.separates = step.report.separates;
  totals_.fractured_m2 = step.report.fractured_m2;
  totals_.vaporised_m2 = step.report.vaporised_m2;
  totals_.groove_record_full = step.report.groove_record_full;
  totals_.elapsed_s = elapsed_s;
}

void LoopStatistics::record_irs_encoded(std::int64_t encode_ns, std::uint64_t irs_sent,
                                        std::uint64_t bytes_sent, std::uint64_t superseded) {
  std::lock_guard lock(mutex_);
  totals_.irs_superseded += superseded;
  ir_encode_ns_.record(encode_ns);
  totals_.irs_sent += irs_sent;
  totals_.ir_bytes_sent += bytes_sent;
}

void LoopStatistics::record_failure(int consecutive, const std::string& what, double elapsed_s) {
  std::lock_guard lock(mutex_);
  ++totals_.failed_steps;
  totals_.max_consecutive_failures = std::max(totals_.max_consecutive_failures, consecutive);
  totals_.last_failure = what;
  totals_.elapsed_s = elapsed_s;
}

void LoopStatistics::record_display_frame(double max_displacement_m) {
  std::lock_guard lock(mutex_);
  totals_.max_surface_displacement_m =
      std::max(totals_.max_surface_displacement_m, max_displacement_m);
}

LoopSummary LoopStatistics::summary() const {
  std::lock_guard lock(mutex_);
  LoopSummary summary = totals_;
  const auto ms = [](std::int64_t ns) { return static_cast<double>(ns) * 1e-6; };
  summary.step_p50_ms = ms(step_ns_.quantile(0.5));
  summary.step_p99_ms = ms(step_ns_.quantile(0.99));
  summary.step_max_ms = ms(step_ns_.max());
  summary.ir_build_p50_ms = ms(ir_build_ns_.quantile(0.5));
  summary.ir_build_p99_ms = ms(ir_build_ns_.quantile(0.99));
  summary.ir_encode_p50_ms = ms(ir_encode_ns_.quantile(0.5));
  summary.ir_encode_p99_ms = ms(ir_encode_ns_.quantile(0.99));
  summary.ir_builds = ir_build_ns_.count();
  return summary;
}

}  // namespace cohaptic
