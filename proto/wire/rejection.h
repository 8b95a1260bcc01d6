// Why a received datagram or control frame was dropped, and how many were, per reason.
//
// The checks and their order are datagram_codec.h's and frame_codec.h's; rate_limited is
// counted by the UDP endpoint (net/), which drops a misbehaving source's datagrams unread.
// The counters are atomics so a monitoring thread may read them while the receiving
// thread counts.
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
  oversized,       ///< longer than kMaxDatagramBytes (a frame: its declared length above the limit)
  truncated,       ///< shorter than an envelope and a tag, or the opened body does not parse
  bad_tag,         ///< authentication failed (wrong key, another slot's key, corrupted or forged),
                   ///< or the sealed header names another sender or sequence than the envelope
  bad_version,     ///< the envelope's or the header's protocol version is not kProtocolVersion
                   ///< (an older peer), or the envelope has flags this version does not know
  wrong_session,   ///< header.session differs from the expected session
  unknown_sender,  ///< the envelope's sender is not one this receiver holds a key for
  replayed,        ///< sequence already seen or older than the replay window, or sealed by
                   ///< another sealer (salt) than the sender's current one, or a stale join
  non_finite,      ///< a NaN or infinite value in the body
  empty,           ///< no body
  cleartext,       ///< not encrypted, and this receiver requires encryption
  rate_limited,    ///< from a source whose datagrams keep failing: dropped unread (net/)
  bad_time,        ///< a clock reading (header or body) outside [0, kMaxClockNs)
};

constexpr std::size_t kRejectionCount = 12;

constexpr std::array<Rejection, kRejectionCount> kAllRejections = {
    Rejection::oversized,   Rejection::truncated,     Rejection::bad_tag,
    Rejection::bad_version, Rejection::wrong_session, Rejection::unknown_sender,
    Rejection::replayed,    Rejection::non_finite,    Rejection::empty,
    Rejection::cleartext,   Rejection::rate_limited,  Rejection::bad_time};

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

  void record(Rejection reason) {
    rejected_[static_cast<std::size_t>(reason)].fetch_add(1, std::memory_order_relaxed);
  }
  void record_accepted() { accepted_.fetch_add(1, std::memory_order_relaxed); }

  /// {"accepted": n, "bad_tag": n, ...}: every reason, zeros included (ready for JSON).
  std::map<std::string, std::uint64_t> snapshot() const;

 private:
  std::array<std::atomic<std::uint64_t>, kRejectionCount> rejected_{};
  std::atomic<std::uint64_t> accepted_{0};
};

}  // namespace cohaptic::wire
