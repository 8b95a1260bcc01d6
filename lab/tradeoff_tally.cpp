#include "lab/tradeoff_tally.h"

#include <algorithm>
#include <cmath>

#include "common/util/percentile.h"

namespace cohaptic {

void TradeoffTally::step(const StepReport& report, double ms) {
  if (report.rebuilt) {
    rebuild_ms_.push_back(report.rebuild_ms);
    rebuild_step_ms_ += ms;
  } else {
    plain_step_ms_.push_back(ms);
  }
}

void TradeoffTally::published(std::size_t bytes) {
  bytes_ += static_cast<double>(bytes);
  ++irs_;
}

void TradeoffTally::sample(const Eigen::Vector3d& held, const Eigen::Vector3d& reference,
                           const Eigen::Vector3d& own) {
  const double error = (held - reference).norm();
  sum_squared_ += error * error;
  worst_ = std::max(worst_, error);
  const double own_error = (held - own).norm();
  own_sum_squared_ += own_error * own_error;
  own_worst_ = std::max(own_worst_, own_error);
}

void TradeoffTally::finish(TradeoffRow& row, const ReferenceTrace& reference,
                           std::size_t users) const {
  const std::size_t samples = reference.positions.size();
  const double duration = static_cast<double>(samples) / reference.sample_rate_hz;
  const double peak = std::max(reference.peak_force, 1e-300);
  const auto count = static_cast<double>(samples * users);
  row.error_rms = std::sqrt(sum_squared_ / count) / peak;
  row.error_max = worst_ / peak;
  row.own_mesh_error_rms = std::sqrt(own_sum_squared_ / count) / peak;
  row.own_mesh_error_max = own_worst_ / peak;
  row.mtilde_ms_p50 = rebuild_ms_.empty() ? 0 : percentile(rebuild_ms_, 0.5);
  row.mtilde_ms_p99 = rebuild_ms_.empty() ? 0 : percentile(rebuild_ms_, 0.99);
  // Medians of the many cheap steps and evaluations, so that a scheduler hiccup on a busy
  // machine does not decide the front; the steps that rebuilt IRs count in full.
  row.evaluation_us = evaluation_us_.empty() ? 0 : percentile(evaluation_us_, 0.5);
  row.ir_bytes_per_s = bytes_ / duration;
  row.irs_sent = irs_;
  const double plain_steps_ms =
      plain_step_ms_.empty()
          ? 0
          : percentile(plain_step_ms_, 0.5) * static_cast<double>(plain_step_ms_.size());
  const double evaluations_ms =
      row.evaluation_us * static_cast<double>(evaluation_us_.size()) / 1000;
  row.cpu_ms_per_s = (rebuild_step_ms_ + plain_steps_ms + evaluations_ms) / duration;
}

}  // namespace cohaptic
