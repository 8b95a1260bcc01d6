// ReplayWindow: which sequence numbers of one sender were already accepted, as in IPsec
// (RFC 4303 §3.4.3): the highest sequence seen and a 64-entry bitmap of the ones below it.
//
// A new highest sequence is accepted (the window slides); an older one is accepted once if
// it is within the last 64 (a reordering link loses nothing in the window); duplicates and
// anything 64 or more below the highest are rejected. The first sequence ever is accepted,
// whatever it is. O(1), no allocation.
#pragma once

#include <cstdint>
#include <optional>

namespace cohaptic::wire {

class ReplayWindow {
 public:
  static constexpr std::uint64_t kSize = 64;

  /// Whether accept(sequence) would succeed; changes nothing.
  bool fresh(std::uint64_t sequence) const;
  /// Records `sequence` and returns true if it is fresh; returns false (and changes
  /// nothing) for a duplicate or a sequence older than the window.
  bool accept(std::uint64_t sequence);
  /// Forgets everything (a new sender in the slot).
  void reset() { *this = ReplayWindow{}; }
  /// Forgets everything, then treats every sequence up to `sequence` as seen: a sender that
  /// said its last sequence was `sequence` is heard from the next one on.
  void start_after(std::uint64_t sequence) {
    started_ = true;
    highest_ = sequence;
    seen_ = ~std::uint64_t{0};
  }
  /// The highest sequence accepted so far.
  std::optional<std::uint64_t> highest() const {
    return started_ ? std::optional<std::uint64_t>(highest_) : std::nullopt;
  }

 private:
  bool started_ = false;
  std::uint64_t highest_ = 0;
  std::uint64_t seen_ = 0;  ///< bit i: sequence highest_ - i was accepted
};

}  // namespace cohaptic::wire
