// Traffic keys: every sender's messages are sealed (aead.h) with a key of its own, derived
// from the session key with libsodium's crypto_kdf (BLAKE2b), context "cohaptic":
//   traffic key of sender s = KDF(session key, id = s)
// for s = k + 1, participant k's key (header.h, sender_of_slot), and s = kJoiningSender,
// the joining key, with which a holder of the session key joins without a slot of its own.
// The server (sender 0) has no key of its own: it seals what it sends to participant k with
// participant k's key, so one key protects one participant's channel in both directions,
// and a participant who holds only its own key can neither read nor forge another's traffic.
// Whoever holds the session key can derive every key: the server, and clients trusted with it.
#pragma once

#include <cstdint>
#include <optional>
#include <variant>

#include "proto/wire/header.h"
#include "proto/wire/session_key.h"

namespace cohaptic::wire {

/// KDF(session, id = sender).
TrafficKey traffic_key(const SessionKey& session, std::uint32_t sender);
inline TrafficKey participant_key(const SessionKey& session, std::uint32_t slot) {
  return traffic_key(session, sender_of_slot(slot));
}
inline TrafficKey joining_key(const SessionKey& session) {
  return traffic_key(session, kJoiningSender);
}

/// What a client holds, from its key file: the session key (it may ask for any slot, and
/// joins with the joining key) or one participant's key (it joins that slot only, with it).
class ClientKeys {
 public:
  explicit ClientKeys(std::variant<SessionKey, ParticipantKey> keys) : keys_(std::move(keys)) {}

  /// A participant key's slot; nullopt with the session key.
  std::optional<std::uint32_t> fixed_slot() const;
  /// The sender the Join is sealed as, and its key.
  std::uint32_t join_sender() const;
  TrafficKey join_key() const;
  /// The traffic key of `slot`; nullopt if these keys cannot make it (another participant's).
  std::optional<TrafficKey> slot_key(std::uint32_t slot) const;

 private:
  std::variant<SessionKey, ParticipantKey> keys_;
};

}  // namespace cohaptic::wire
