// Histogram: fixed-resolution counts of durations, recorded without allocation (for the
// haptic loop's period and latencies), summarised as p50/p99/max.
// Values above the range land in the last bin; the exact maximum is kept separately.
// One thread records; others may read a summary at the same time (the client's I/O thread
// reports the haptic thread's figures while it runs): every field is accessed through
// atomic references (plain loads and stores on x86-64), so a concurrent reader sees each
// field whole, at most a record or two behind the count.
// Units: whatever the caller records (ns in cohaptic).
#pragma once

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <vector>

namespace cohaptic {

class Histogram {
 public:
  /// Bins of `resolution` covering [0, resolution * bins).
  Histogram(std::int64_t resolution, std::size_t bins)
      : resolution_(resolution), counts_(bins, 0) {}

  /// The recording thread only.
  void record(std::int64_t value) noexcept {
    const std::int64_t clamped = std::max<std::int64_t>(0, value);
    const auto bin =
        std::min<std::size_t>(static_cast<std::size_t>(clamped / resolution_), counts_.size() - 1);
    store(counts_[bin], load(counts_[bin]) + 1);
    if (value > load(max_)) store(max_, value);
    store(sum_, load(sum_) + static_cast<double>(value));
    // Last, and released: a reader that acquires the count sees the bins it counts.
    std::atomic_ref<std::uint64_t>(count_).store(load(count_) + 1, std::memory_order_release);
  }

  std::uint64_t count() const {
    return std::atomic_ref<std::uint64_t>(const_cast<std::uint64_t&>(count_))
        .load(std::memory_order_acquire);
  }
  std::int64_t max() const { return count() ? load(max_) : 0; }
  double mean() const {
    const std::uint64_t n = count();
    return n ? load(sum_) / static_cast<double>(n) : 0;
  }
  /// Upper edge of the bin holding the q-quantile (0 < q <= 1); 0 when empty.
  std::int64_t quantile(double q) const {
    const std::uint64_t n = count();
    if (n == 0) return 0;
    const std::int64_t largest = load(max_);
    const auto target =
        std::max<std::uint64_t>(static_cast<std::uint64_t>(q * static_cast<double>(n) + 0.5), 1);
    std::uint64_t seen = 0;
    for (std::size_t b = 0; b < counts_.size(); ++b) {
      seen += load(counts_[b]);
      if (seen >= target)
        return std::min<std::int64_t>((static_cast<std::int64_t>(b) + 1) * resolution_, largest);
    }
    return largest;
  }

 private:
  template <class T>
  static T load(const T& field) noexcept {
    return std::atomic_ref<T>(const_cast<T&>(field)).load(std::memory_order_relaxed);
  }
  template <class T>
  static void store(T& field, T value) noexcept {
    std::atomic_ref<T>(field).store(value, std::memory_order_relaxed);
  }

  std::int64_t resolution_;
  std::vector<std::uint64_t> counts_;
  std::uint64_t count_ = 0;
  std::int64_t max_ = 0;
  double sum_ = 0;
};

}  // namespace cohaptic
