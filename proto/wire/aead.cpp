#include "proto/wire/aead.h"

#include <sodium.h>

#include "proto/wire/sodium_ready.h"

namespace cohaptic::wire {

static_assert(crypto_aead_xchacha20poly1305_ietf_ABYTES == kTagBytes);
static_assert(crypto_aead_xchacha20poly1305_ietf_NPUBBYTES == std::tuple_size_v<Nonce>);
static_assert(crypto_aead_xchacha20poly1305_ietf_KEYBYTES == sizeof(TrafficKey::bytes));

Nonce make_nonce(Channel channel, const Envelope& envelope) {
  Nonce nonce{};
  write_le(envelope.salt, 8, nonce.data());
  write_le(envelope.sender, 4, nonce.data() + 8);
  write_le(static_cast<std::uint32_t>(channel), 4, nonce.data() + 12);
  write_le(envelope.sequence, 8, nonce.data() + 16);
  return nonce;
}

std::uint64_t random_salt() {
  ensure_sodium();
  std::uint64_t salt = 0;
  randombytes_buf(&salt, sizeof salt);
  return salt;
}

void seal_in_place(std::span<std::uint8_t> message, std::size_t clear_bytes, const Nonce& nonce,
                   const TrafficKey& key, bool encrypt) {
  std::uint8_t* tag = message.data() + message.size() - kTagBytes;
  const std::size_t body_bytes = message.size() - kTagBytes - clear_bytes;
  std::uint8_t* body = message.data() + clear_bytes;
  // Encrypted: the clear part is the associated data. In clear: everything before the tag is.
  const std::size_t associated = encrypt ? clear_bytes : clear_bytes + body_bytes;
  crypto_aead_xchacha20poly1305_ietf_encrypt_detached(
      body, tag, nullptr, body, encrypt ? body_bytes : 0, message.data(), associated, nullptr,
      nonce.data(), key.bytes.data());
}

std::optional<std::span<const std::uint8_t>> open_sealed(std::span<const std::uint8_t> message,
                                                         std::size_t clear_bytes,
                                                         const Nonce& nonce, const TrafficKey& key,
                                                         bool encrypted,
                                                         std::span<std::uint8_t> plaintext) {
  if (message.size() < clear_bytes + kTagBytes) return std::nullopt;
  const std::uint8_t* tag = message.data() + message.size() - kTagBytes;
  const std::size_t body_bytes = message.size() - kTagBytes - clear_bytes;
  const std::uint8_t* body = message.data() + clear_bytes;
  if (!encrypted) {
    // No ciphertext (length 0: `body` is only a valid pointer) and no output: the tag alone.
    if (crypto_aead_xchacha20poly1305_ietf_decrypt_detached(
            nullptr, nullptr, body, 0, tag, message.data(), clear_bytes + body_bytes, nonce.data(),
            key.bytes.data()) != 0)
      return std::nullopt;
    return std::span(body, body_bytes);
  }
  if (plaintext.size() < body_bytes) return std::nullopt;
  if (crypto_aead_xchacha20poly1305_ietf_decrypt_detached(
          plaintext.data(), nullptr, body, body_bytes, tag, message.data(), clear_bytes,
          nonce.data(), key.bytes.data()) != 0)
    return std::nullopt;
  return std::span<const std::uint8_t>(plaintext.data(), body_bytes);
}

}  // namespace cohaptic::wire
