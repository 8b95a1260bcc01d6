#include "proto/wire/authenticated.h"

#include <sodium.h>

#include <algorithm>

namespace cohaptic::wire {

static_assert(crypto_auth_BYTES == kTagBytes, "crypto_auth is HMAC-SHA-512-256: 32-byte tags");
static_assert(crypto_auth_KEYBYTES == sizeof(SessionKey::bytes), "crypto_auth takes 32-byte keys");

std::array<std::uint8_t, kTagBytes> authentication_tag(std::span<const std::uint8_t> message, const SessionKey& key) {
  std::array<std::uint8_t, kTagBytes> tag{};
  crypto_auth(tag.data(), message.data(), message.size(), key.bytes.data());
  return tag;
}

bool verify_tag(std::span<const std::uint8_t> message, std::span<const std::uint8_t> tag, const SessionKey& key) {
  return tag.size() == kTagBytes && crypto_auth_verify(tag.data(), message.data(), message.size(), key.bytes.data()) == 0;
}

std::vector<std::uint8_t> seal(std::span<const std::uint8_t> payload, const SessionKey& key) {
  std::vector<std::uint8_t> packet(payload.size() + kTagBytes);
  std::copy(payload.begin(), payload.end(), packet.begin());
  crypto_auth(packet.data() + payload.size(), payload.data(), payload.size(), key.bytes.data());
  return packet;
}

std::optional<std::span<const std::uint8_t>> open(std::span<const std::uint8_t> packet, const SessionKey& key) {
  if (packet.size() < kTagBytes) return std::nullopt;
  const std::span<const std::uint8_t> payload = packet.first(packet.size() - kTagBytes);
  if (!verify_tag(payload, packet.last(kTagBytes), key)) return std::nullopt;
  return payload;
}

}  // namespace cohaptic::wire
