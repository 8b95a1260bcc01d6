// TradeoffTally: what a trade-off run adds up while it plays its workload (lab/tradeoff.h),
// whatever the body model: the simulation steps' times, the IRs published and their bytes,
// the evaluations' times, and each sample's force error against the reference and against
// the setting's own full solve. finish() turns them into a TradeoffRow's figures, so every
// model's row is measured the same way. Units: ms, µs, bytes, N (errors over the peak).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "common/sim/step_report.h"
#include "lab/tradeoff.h"

namespace cohaptic {

class TradeoffTally {
 public:
  /// A simulation step that took `ms` of wall time: a step that rebuilt IRs counts in full,
  /// the others at their median (robust to a scheduler hiccup).
  void step(const StepReport& report, double ms);
  /// An IR handed to its user, `bytes` long on the wire.
  void published(std::size_t bytes);
  /// One haptic evaluation's time [µs].
  void evaluation(double us) { evaluation_us_.push_back(us); }
  /// One user's force at one sample: `held` (what the client outputs) against the
  /// reference's and against the setting's own full solve [N].
  void sample(const Eigen::Vector3d& held, const Eigen::Vector3d& reference,
              const Eigen::Vector3d& own);

  /// Fills row's errors, M~ times, evaluation time, IR bytes per second, CPU per second and
  /// IRs sent, for a workload of `samples` samples of `users` users.
  void finish(TradeoffRow& row, const ReferenceTrace& reference, std::size_t users) const;

 private:
  std::vector<double> rebuild_ms_, plain_step_ms_, evaluation_us_;
  double rebuild_step_ms_ = 0, bytes_ = 0;
  double sum_squared_ = 0, worst_ = 0, own_sum_squared_ = 0, own_worst_ = 0;
  int irs_ = 0;
};

}  // namespace cohaptic
