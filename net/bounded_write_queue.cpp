#include "net/bounded_write_queue.h"

#include <algorithm>

#include "common/util/error.h"

namespace cohaptic::net {

BoundedWriteQueue::BoundedWriteQueue(std::size_t max_waiting) : max_waiting_(max_waiting) {
  if (max_waiting == 0)
    throw Error("BoundedWriteQueue: at least one frame must be allowed to wait");
}

BoundedWriteQueue::Push BoundedWriteQueue::push(std::vector<std::uint8_t> frame, FrameKind kind) {
  if (waiting_.size() < max_waiting_) {
    waiting_.push_back({std::move(frame), kind});
    return Push::queued;
  }
  const auto is_newest_wins = [](const Entry& entry) {
    return entry.kind == FrameKind::newest_wins;
  };
  const auto superseding = std::count_if(waiting_.begin(), waiting_.end(), is_newest_wins) +
                           (kind == FrameKind::newest_wins ? 1 : 0);
  if (superseding < 2) return Push::refused;  // nothing waiting is superseded by a newer frame
  waiting_.erase(std::find_if(waiting_.begin(), waiting_.end(), is_newest_wins));
  ++dropped_;
  waiting_.push_back({std::move(frame), kind});
  return Push::queued_after_drop;
}

const std::vector<std::uint8_t>* BoundedWriteQueue::begin_write() {
  if (writing_ || waiting_.empty()) return nullptr;
  writing_ = std::move(waiting_.front().bytes);
  waiting_.pop_front();
  return &*writing_;
}

void BoundedWriteQueue::end_write() { writing_.reset(); }

}  // namespace cohaptic::net
