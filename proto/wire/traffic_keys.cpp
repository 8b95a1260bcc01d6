#include "proto/wire/traffic_keys.h"

#include <sodium.h>

#include "proto/wire/sodium_ready.h"

namespace cohaptic::wire {

static_assert(crypto_kdf_KEYBYTES == sizeof(SessionKey::bytes),
              "crypto_kdf takes 32-byte master keys");
static_assert(crypto_kdf_CONTEXTBYTES == 8, "crypto_kdf contexts are 8 bytes");

TrafficKey traffic_key(const SessionKey& session, std::uint32_t sender) {
  ensure_sodium();
  TrafficKey key;
  crypto_kdf_derive_from_key(key.bytes.data(), key.bytes.size(), sender, "cohaptic",
                             session.bytes.data());
  return key;
}

std::optional<std::uint32_t> ClientKeys::fixed_slot() const {
  if (const auto* participant = std::get_if<ParticipantKey>(&keys_)) return participant->slot;
  return std::nullopt;
}

std::uint32_t ClientKeys::join_sender() const {
  if (const auto slot = fixed_slot()) return sender_of_slot(*slot);
  return kJoiningSender;
}

TrafficKey ClientKeys::join_key() const {
  if (const auto* participant = std::get_if<ParticipantKey>(&keys_)) return participant->key;
  return joining_key(std::get<SessionKey>(keys_));
}

std::optional<TrafficKey> ClientKeys::slot_key(std::uint32_t slot) const {
  if (const auto* participant = std::get_if<ParticipantKey>(&keys_))
    return participant->slot == slot ? std::optional<TrafficKey>(participant->key) : std::nullopt;
  return participant_key(std::get<SessionKey>(keys_), slot);
}

}  // namespace cohaptic::wire
