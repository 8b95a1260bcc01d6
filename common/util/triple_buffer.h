// TripleBuffer: hands the newest value from one writer thread to one reader thread without
// locks, waiting or copying on the reader's side.
//
// Three slots: the writer fills its back slot and publishes it; the reader takes the
// newest published slot when it asks. The reader never sees a half-written value and
// never frees anything: a slot's old contents are replaced by the writer, on the writer's
// thread (so an IR's memory is released by the I/O thread, never by the haptic thread).
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <utility>

namespace cohaptic {

template <typename T>
class TripleBuffer {
 public:
  /// Writer: the slot to fill next.
  T& back() noexcept { return slots_[back_]; }
  /// Writer: make back() the newest value.
  void publish() noexcept {
    const std::uint8_t previous =
        middle_.exchange(static_cast<std::uint8_t>(back_ | kFresh), std::memory_order_acq_rel);
    back_ = previous & kIndex;
  }

  /// Reader: switch to the newest published value if there is one; true if it changed.
  bool update() noexcept {
    if (!(middle_.load(std::memory_order_relaxed) & kFresh)) return false;
    const std::uint8_t previous = middle_.exchange(front_, std::memory_order_acq_rel);
    front_ = previous & kIndex;
    return true;
  }
  /// Reader: the value last taken by update().
  const T& front() const noexcept { return slots_[front_]; }

 private:
  static constexpr std::uint8_t kIndex = 0b011;
  static constexpr std::uint8_t kFresh = 0b100;
  std::array<T, 3> slots_{};
  std::uint8_t back_ = 0;                // writer's
  std::uint8_t front_ = 1;               // reader's
  std::atomic<std::uint8_t> middle_{2};  // shared: index of the spare slot, and whether it is fresh
};

}  // namespace cohaptic
