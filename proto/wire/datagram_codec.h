// UDP datagrams on the wire: one serialized Datagram followed by its authentication tag
// (authenticated.h), at most kMaxDatagramBytes in all.
//
// Receiving runs these checks in this order, the first failure naming the Rejection:
//   size (oversized; truncated if shorter than a tag), tag (bad_tag), parse (truncated),
//   header version (bad_version), session (wrong_session, if one is expected),
//   sender (unknown_sender; inspector only), body present (empty), every double finite
//   (non_finite), every clock reading in [0, kMaxClockNs) (bad_time), replay (replayed;
//   inspector only).
// Replay comes last so that a packet failing any other check never moves a replay window.
// decode_datagram() is the stateless part; DatagramInspector adds the allowed senders,
// one ReplayWindow per sender and counters per reason. Neither throws on any input.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <utility>
#include <variant>
#include <vector>

#include "cohaptic/messages.pb.h"
#include "proto/wire/authenticated.h"
#include "proto/wire/header.h"
#include "proto/wire/rejection.h"
#include "proto/wire/replay_window.h"
#include "proto/wire/session_key.h"

namespace cohaptic::wire {

/// Serialized `datagram` followed by its tag. Throws cohaptic::Error if that exceeds
/// kMaxDatagramBytes.
std::vector<std::uint8_t> encode_datagram(const Datagram& datagram, const SessionKey& key);
/// The same into `out`, reusing its capacity (no allocation once it is large enough).
void encode_datagram(const Datagram& datagram, const SessionKey& key, std::vector<std::uint8_t>& out);

/// The checks that need no state: everything but sender and replay.
std::variant<Datagram, Rejection> decode_datagram(std::span<const std::uint8_t> bytes, const SessionKey& key,
                                                  std::optional<std::uint64_t> expected_session = std::nullopt);

/// The bound of every clock reading a datagram carries (header.sender_time_ns and the
/// body's times): 2^61 ns, 73 years of a monotonic clock. Within it, the receivers' clock
/// arithmetic (offsets, conversions between clocks, ages, intervals) cannot overflow.
constexpr std::int64_t kMaxClockNs = std::int64_t{1} << 61;

/// empty if `datagram` has no body, non_finite if a double in its body is NaN or infinite
/// (a ToolSample's position is checked even when it is marked invalid: send zeros),
/// bad_time if a clock reading in its header or body is outside [0, kMaxClockNs).
std::optional<Rejection> body_rejection(const Datagram& datagram);

/// The receiving side of a UDP socket: validates, counts, and keeps a replay window per
/// allowed sender. Not thread-safe (one receiving thread), except counters(), which any
/// thread may read. inspect() allocates nothing beyond the parsed message.
class DatagramInspector {
 public:
  explicit DatagramInspector(const SessionKey& key, std::optional<std::uint64_t> expected_session = std::nullopt);

  /// A client learns its session from the Welcome; nullopt accepts any session.
  void set_expected_session(std::optional<std::uint64_t> session) { session_ = session; }
  std::optional<std::uint64_t> expected_session() const { return session_; }

  /// Accepts datagrams from `sender` (Header.sender), with a fresh replay window; resets
  /// the window if the sender was already allowed (a new user in the slot).
  void allow_sender(std::uint32_t sender);
  void forget_sender(std::uint32_t sender);
  bool allows(std::uint32_t sender) const { return find(sender) != nullptr; }
  /// The replay window of `sender`, or null if it is not allowed.
  const ReplayWindow* window(std::uint32_t sender) const { return find(sender); }

  /// The datagram if it passes every check; otherwise nullopt, with the reason counted
  /// and available from last_rejection(). Never throws.
  std::optional<Datagram> inspect(std::span<const std::uint8_t> bytes);
  /// The reason the last inspect() rejected its datagram, nullopt if it was accepted.
  std::optional<Rejection> last_rejection() const { return last_; }

  const RejectionCounters& counters() const { return counters_; }

 private:
  const ReplayWindow* find(std::uint32_t sender) const;
  ReplayWindow* find(std::uint32_t sender) {
    return const_cast<ReplayWindow*>(std::as_const(*this).find(sender));
  }
  std::nullopt_t reject(Rejection reason);

  SessionKey key_;
  std::optional<std::uint64_t> session_;
  std::vector<std::pair<std::uint32_t, ReplayWindow>> windows_;  ///< few senders: a flat list
  RejectionCounters counters_;
  std::optional<Rejection> last_;
};

}  // namespace cohaptic::wire
