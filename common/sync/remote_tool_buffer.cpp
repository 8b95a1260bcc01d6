#include "common/sync/remote_tool_buffer.h"

#include <fmt/format.h>

#include <algorithm>

#include "common/util/error.h"

namespace cohaptic {

namespace {
constexpr std::int64_t kAgeBinNs = 250'000;
constexpr std::int64_t kAdaptiveMarginNs = 1'000'000;
}  // namespace

PlayoutPolicy parse_playout_policy(const std::string& text) {
  if (text == "newest") return PlayoutPolicy::newest;
  if (text == "fixed") return PlayoutPolicy::fixed;
  if (text == "adaptive") return PlayoutPolicy::adaptive;
  throw Error(
      fmt::format("unknown playout policy '{}' (expected newest, fixed or adaptive)", text));
}

const char* to_string(PlayoutPolicy policy) {
  switch (policy) {
    case PlayoutPolicy::newest:
      return "newest";
    case PlayoutPolicy::fixed:
      return "fixed";
    case PlayoutPolicy::adaptive:
      return "adaptive";
  }
  return "?";
}

RemoteToolBuffer::RemoteToolBuffer(PlayoutPolicy policy, std::int64_t fixed_delay_ns) noexcept
    : policy_(policy), fixed_delay_ns_(fixed_delay_ns), adaptive_delay_ns_(fixed_delay_ns) {
  age_bin_of_slot_.fill(-1);
}

void RemoteToolBuffer::add(std::int64_t sample_time_ns, std::int64_t arrival_ns,
                           const Eigen::Vector3d& position, bool valid) noexcept {
  if (count_ > 0 && sample_time_ns <= sample(0).time) {
    ++dropped_;
    return;
  }
  // The slot being overwritten leaves the age window.
  if (age_bin_of_slot_[head_] >= 0) --age_histogram_[age_bin_of_slot_[head_]];
  const std::int64_t age = std::max<std::int64_t>(0, arrival_ns - sample_time_ns);
  const auto bin = static_cast<std::int16_t>(std::min<std::int64_t>(age / kAgeBinNs, kAgeBins - 1));
  ++age_histogram_[bin];
  age_bin_of_slot_[head_] = bin;

  samples_[head_] = {sample_time_ns, position, valid && position.allFinite()};
  head_ = (head_ + 1) % kCapacity;
  count_ = std::min(count_ + 1, kCapacity);

  if (policy_ == PlayoutPolicy::adaptive) {
    int total = 0;
    for (std::uint16_t n : age_histogram_) total += n;
    int seen = 0, percentile_bin = 0;
    for (int b = 0; b < kAgeBins; ++b) {
      seen += age_histogram_[b];
      if (seen * 100 >= total * 95) {
        percentile_bin = b;
        break;
      }
    }
    adaptive_delay_ns_ = (percentile_bin + 1) * kAgeBinNs + kAdaptiveMarginNs;
  }
}

std::int64_t RemoteToolBuffer::playout_delay_ns() const noexcept {
  switch (policy_) {
    case PlayoutPolicy::newest:
      return 0;
    case PlayoutPolicy::fixed:
      return fixed_delay_ns_;
    case PlayoutPolicy::adaptive:
      return adaptive_delay_ns_;
  }
  return 0;
}

PlayoutQuery RemoteToolBuffer::at(std::int64_t now_ns) const noexcept {
  PlayoutQuery query;
  if (count_ == 0) return query;
  const Sample& newest = sample(0);
  const std::int64_t target = now_ns - playout_delay_ns();
  if (policy_ == PlayoutPolicy::newest || target >= newest.time) {
    query = {newest.position, newest.valid, now_ns - newest.time};
    return query;
  }
  // Walk back to the samples around the target time.
  for (int age = 1; age < count_; ++age) {
    const Sample& older = sample(age);
    const Sample& newer = sample(age - 1);
    if (older.time <= target) {
      if (!older.valid || !newer.valid) return {older.position, false, now_ns - older.time};
      const double s =
          static_cast<double>(target - older.time) / static_cast<double>(newer.time - older.time);
      return {older.position + s * (newer.position - older.position), true, now_ns - target};
    }
  }
  const Sample& oldest = sample(count_ - 1);
  return {oldest.position, oldest.valid, now_ns - oldest.time};
}

}  // namespace cohaptic
