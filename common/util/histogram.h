// Histogram: fixed-resolution counts of durations, recorded without allocation (for the
// haptic loop's period and latencies), summarised as p50/p99/max afterwards.
// Values above the range land in the last bin; the exact maximum is kept separately.
// Units: whatever the caller records (ns in cohaptic).
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

namespace cohaptic {

class Histogram {
 public:
  /// Bins of `resolution` covering [0, resolution * bins).
  Histogram(std::int64_t resolution, std::size_t bins) : resolution_(resolution), counts_(bins, 0) {}

  void record(std::int64_t value) noexcept {
    const std::int64_t clamped = std::max<std::int64_t>(0, value);
    const auto bin = std::min<std::size_t>(static_cast<std::size_t>(clamped / resolution_), counts_.size() - 1);
    ++counts_[bin];
    ++count_;
    max_ = std::max(max_, value);
    sum_ += static_cast<double>(value);
  }

  std::uint64_t count() const { return count_; }
  std::int64_t max() const { return count_ ? max_ : 0; }
  double mean() const { return count_ ? sum_ / static_cast<double>(count_) : 0; }
  /// Upper edge of the bin holding the q-quantile (0 < q <= 1); 0 when empty.
  std::int64_t quantile(double q) const {
    if (count_ == 0) return 0;
    const auto target = static_cast<std::uint64_t>(q * static_cast<double>(count_) + 0.5);
    std::uint64_t seen = 0;
    for (std::size_t b = 0; b < counts_.size(); ++b) {
      seen += counts_[b];
      if (seen >= std::max<std::uint64_t>(target, 1)) return std::min<std::int64_t>((static_cast<std::int64_t>(b) + 1) * resolution_, max_);
    }
    return max_;
  }

 private:
  std::int64_t resolution_;
  std::vector<std::uint64_t> counts_;
  std::uint64_t count_ = 0;
  std::int64_t max_ = 0;
  double sum_ = 0;
};

}  // namespace cohaptic
