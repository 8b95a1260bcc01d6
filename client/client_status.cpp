#include "client/client_status.h"

namespace cohaptic {

wire::ClientStatus client_status(const HapticProgress& progress, const HapticMetrics& metrics,
                                 double timer_floor_p99_us, const Histogram& one_way_delay_ns) {
  const auto quantile = [](const Histogram& h, double scale) {
    return static_cast<double>(h.quantile(0.99)) * scale;
  };
  wire::ClientStatus status;
  status.set_haptic_rate_hz(
      progress.elapsed_s > 0 ? static_cast<double>(progress.ticks) / progress.elapsed_s : 0.0);
  status.set_period_p99_us(quantile(metrics.period_ns, 1e-3));
  status.set_missed_deadlines(progress.missed_deadlines);
  status.set_ir_age_p99_ms(quantile(metrics.ir_age_ns, 1e-6));
  status.set_one_way_delay_p99_ms(quantile(one_way_delay_ns, 1e-6));
  status.set_timer_floor_p99_us(timer_floor_p99_us);
  status.set_peak_force(progress.peak_force);
  status.set_ticks(progress.ticks);
  status.set_elapsed_s(progress.elapsed_s);
  status.set_final(progress.finished);
  status.set_fades(progress.fades.count);
  status.set_fade_total_s(progress.fades.total_s);
  status.set_fade_longest_s(progress.fades.longest_s);
  status.set_clamped_ticks(progress.clamped);
  status.set_ir_age_max_ms(static_cast<double>(metrics.ir_age_ns.max()) * 1e-6);
  return status;
}

}  // namespace cohaptic
