// UDP datagrams on the wire (protocol 3): [envelope (envelope.h)][body: one serialized
// Datagram, encrypted or in clear][16-byte tag (aead.h)], at most kMaxDatagramBytes.
//
// Receiving runs these checks in this order, the first failure naming the Rejection:
//   size (oversized; truncated if shorter than envelope and tag), envelope version and
//   flags (bad_version), encryption required (cleartext), sender (unknown_sender; the
//   inspector only: a sender it holds no key for), tag under the sender's key (bad_tag),
//   parse (truncated), header version (bad_version), header sender and sequence equal to
//   the envelope's (bad_tag), session (wrong_session, if one is expected), salt (replayed,
//   the inspector only: sealed by another sealer than the sender's current one), body
//   present (empty), every double finite (non_finite), every clock reading in
//   [0, kMaxClockNs) (bad_time), replay window (replayed; inspector).
// The sender is checked before the tag, so that a datagram from no one costs no
// cryptography; the replay window comes last, so that a datagram failing any other check
// never moves it. decode_datagram() is the stateless part; DatagramInspector adds the
// allowed senders with their keys and salts, one ReplayWindow per sender and counters per
// reason. Neither throws on any input.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <utility>
#include <variant>
#include <vector>

#include "cohaptic/messages.pb.h"
#include "proto/wire/aead.h"
#include "proto/wire/header.h"
#include "proto/wire/rejection.h"
#include "proto/wire/replay_window.h"
#include "proto/wire/session_key.h"

namespace cohaptic::wire {

constexpr std::size_t kMaxDatagramBytes = 1400;  ///< a whole datagram, below a typical path MTU
constexpr std::size_t kDatagramOverheadBytes = kEnvelopeBytes + kTagBytes;

/// How a message is sealed: under which key, by which sealer (its salt), encrypted or in clear.
struct SealWith {
  const TrafficKey& key;
  std::uint64_t salt = 0;
  bool encrypt = true;
};

/// The sealed bytes of `datagram`, whose header gives the envelope's sender and sequence.
/// Throws cohaptic::Error if they exceed kMaxDatagramBytes.
std::vector<std::uint8_t> encode_datagram(const Datagram& datagram, const SealWith& seal);
/// The same into `out`, reusing its capacity (no allocation once it is large enough).
void encode_datagram(const Datagram& datagram, const SealWith& seal,
                     std::vector<std::uint8_t>& out);

/// The checks that need no state (all but sender, salt and replay), with `key` for
/// whichever sender the envelope names.
std::variant<Datagram, Rejection> decode_datagram(
    std::span<const std::uint8_t> bytes, const TrafficKey& key,
    std::optional<std::uint64_t> expected_session = std::nullopt, bool allow_cleartext = false);

/// The bound of every clock reading a datagram carries (header.sender_time_ns and the
/// body's times): 2^61 ns, 73 years of a monotonic clock. Within it, the receivers' clock
/// arithmetic (offsets, conversions between clocks, ages, intervals) cannot overflow.
constexpr std::int64_t kMaxClockNs = std::int64_t{1} << 61;

/// empty if `datagram` has no body, non_finite if a double in its body is NaN or infinite
/// (a ToolSample's position is checked even when it is marked invalid: send zeros),
/// bad_time if a clock reading in its header or body is outside [0, kMaxClockNs).
std::optional<Rejection> body_rejection(const Datagram& datagram);

/// The receiving side of a UDP socket: validates, counts, and keeps for each allowed
/// sender its key, its sealer's salt and a replay window. Not thread-safe (one receiving
/// thread), except counters(), which any thread may read. inspect() allocates nothing
/// beyond the parsed message.
class DatagramInspector {
 public:
  /// `allow_cleartext`: accept datagrams sent in clear (authenticated, not encrypted).
  explicit DatagramInspector(std::optional<std::uint64_t> expected_session = std::nullopt,
                             bool allow_cleartext = false);

  /// A client learns its session from the Welcome; nullopt accepts any session.
  void set_expected_session(std::optional<std::uint64_t> session) { session_ = session; }
  std::optional<std::uint64_t> expected_session() const { return session_; }

  /// Accepts datagrams from `sender` sealed with `key` by the sealer whose salt is `salt`,
  /// with sequences above `last_sequence` (the sender's last one before, as it told us),
  /// in a fresh replay window. Replaces what was allowed for `sender` before.
  void allow_sender(std::uint32_t sender, const TrafficKey& key, std::uint64_t salt,
                    std::uint64_t last_sequence = 0);
  void forget_sender(std::uint32_t sender);
  bool allows(std::uint32_t sender) const { return find(sender) != nullptr; }
  /// The replay window of `sender`, or null if it is not allowed.
  const ReplayWindow* window(std::uint32_t sender) const;

  /// The datagram if it passes every check; otherwise nullopt, with the reason counted
  /// and available from last_rejection(). Never throws.
  std::optional<Datagram> inspect(std::span<const std::uint8_t> bytes);
  /// The reason the last inspect() rejected its datagram, nullopt if it was accepted.
  std::optional<Rejection> last_rejection() const { return last_; }
  /// Counts a datagram dropped before inspection (rate_limited).
  void count_unread(Rejection reason) { counters_.record(reason); }

  const RejectionCounters& counters() const { return counters_; }

 private:
  struct Sender {
    std::uint32_t id = 0;
    TrafficKey key;
    std::uint64_t salt = 0;
    ReplayWindow window;
  };
  const Sender* find(std::uint32_t sender) const;
  Sender* find(std::uint32_t sender) {
    return const_cast<Sender*>(std::as_const(*this).find(sender));
  }
  std::nullopt_t reject(Rejection reason);

  std::optional<std::uint64_t> session_;
  bool allow_cleartext_;
  std::vector<Sender> senders_;  ///< few senders: a flat list
  RejectionCounters counters_;
  std::optional<Rejection> last_;
};

}  // namespace cohaptic::wire
