#include "common/sync/clock_offset.h"

namespace cohaptic {

ClockOffsetEstimator::ClockOffsetEstimator(std::size_t window)
    : samples_(window == 0 ? 1 : window) {}

void ClockOffsetEstimator::add(std::int64_t t0, std::int64_t t1, std::int64_t t2, std::int64_t t3) {
  const std::int64_t round_trip = (t3 - t0) - (t2 - t1);
  if (round_trip < 0) return;
  samples_[next_] = {((t1 - t0) + (t2 - t3)) / 2, round_trip};
  next_ = (next_ + 1) % samples_.size();
  if (count_ < samples_.size()) ++count_;
  best_ = 0;
  for (std::size_t i = 1; i < count_; ++i)
    if (samples_[i].round_trip < samples_[static_cast<std::size_t>(best_)].round_trip)
      best_ = static_cast<long>(i);
}

}  // namespace cohaptic
