#include "proto/wire/replay_window.h"

namespace cohaptic::wire {

bool ReplayWindow::fresh(std::uint64_t sequence) const {
  if (!started_ || sequence > highest_) return true;
  const std::uint64_t age = highest_ - sequence;
  return age < kSize && !((seen_ >> age) & 1u);
}

bool ReplayWindow::accept(std::uint64_t sequence) {
  if (!fresh(sequence)) return false;
  if (!started_) {
    started_ = true;
    highest_ = sequence;
    seen_ = 1;
  } else if (sequence > highest_) {
    const std::uint64_t shift = sequence - highest_;
    seen_ = (shift >= kSize ? 0 : seen_ << shift) | 1u;
    highest_ = sequence;
  } else {
    seen_ |= std::uint64_t{1} << (highest_ - sequence);
  }
  return true;
}

}  // namespace cohaptic::wire
