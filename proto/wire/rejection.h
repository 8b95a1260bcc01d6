// Why a received datagram was dropped, and how many were, per reason.
//
// Reasons in the order the checks run (datagram_codec.h): size, tag, parse, version,
// session, sender, body present, finite values, clock readings in range, replay. The counters are atomics so a
// monitoring thread may read them while the receiving thread counts.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <string_view>

namespace cohaptic::wire {

enum class Rejection : std::uint8_t {
  oversized,       ///< longer than kMaxDatagramBytes
  truncated,       ///< shorter than a tag, or the authenticated payload does not parse
  bad_tag,         ///< authentication failed (wrong key, corrupted or forged)
  bad_version,     ///< header.protocol_version != kProtocolVersion (or no header)
  wrong_session,   ///< header.session differs from the expected session
  unknown_sender,  ///< header.sender is not an allowed sender
  replayed,        ///< sequence already seen, or older than the replay window
  non_finite,      ///< a NaN or infinite value in the body
  empty,           ///< no body
  bad_time,        ///< a clock reading (header or body) outside [0, kMaxClockNs)
};

constexpr std::size_t kRejectionCount = 10;

constexpr std::array<Rejection, kRejectionCount> kAllRejections = {
    Rejection::oversized,      Rejection::truncated, Rejection::bad_tag,    Rejection::bad_version, Rejection::wrong_session,
    Rejection::unknown_sender, Rejection::replayed,  Rejection::non_finite, Rejection::empty,       Rejection::bad_time};

/// "oversized", "truncated", "bad_tag", ...: the enumerator's name.
std::string_view to_string(Rejection reason);

class RejectionCounters {
 public:
  std::uint64_t count(Rejection reason) const {
    return rejected_[static_cast<std::size_t>(reason)].load(std::memory_order_relaxed);
  }
  std::uint64_t accepted() const { return accepted_.load(std::memory_order_relaxed); }
  /// Sum over every reason.
  std::uint64_t rejected() const;

  void record(Rejection reason) { rejected_[static_cast<std::size_t>(reason)].fetch_add(1, std::memory_order_relaxed); }
  void record_accepted() { accepted_.fetch_add(1, std::memory_order_relaxed); }

  /// {"accepted": n, "bad_tag": n, ...}: every reason, zeros included (ready for JSON).
  std::map<std::string, std::uint64_t> snapshot() const;

 private:
  std::array<std::atomic<std::uint64_t>, kRejectionCount> rejected_{};
  std::atomic<std::uint64_t> accepted_{0};
};

}  // namespace cohaptic::wire
