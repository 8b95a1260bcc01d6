// Sealing with an AEAD, XChaCha20-Poly1305 (IETF construction, libsodium). A sealed
// message is [clear part][body][16-byte tag]; the clear part is the envelope (envelope.h),
// behind a frame's length for frames.
//   - Encrypted (the default): the body is encrypted; the tag covers the clear part, as
//     associated data, and the ciphertext.
//   - In clear (--no-encryption): the body stays readable; the tag covers the clear part
//     and the body alike, so the message is still authenticated, only not confidential.
// The 24-byte nonce is salt (8) | sender (4) | channel (4) | sequence (8), little-endian.
// Under one key it never repeats: a key is used only by the senders of one channel pair
// (participant k and the server for participant k's key; joiners and the server for the
// joining key); the sender field keeps them apart; a sealer's sequence only increases;
// each sealer draws its salt at random (64 bits) when it is made, so a restarted or
// reconnected process never reuses an earlier sealer's nonces; and the channel field keeps
// a sealer's datagrams and frames apart.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

#include "proto/wire/envelope.h"
#include "proto/wire/session_key.h"

namespace cohaptic::wire {

enum class Channel : std::uint32_t { datagram = 1, frame = 2 };

constexpr std::size_t kTagBytes = 16;
using Nonce = std::array<std::uint8_t, 24>;

Nonce make_nonce(Channel channel, const Envelope& envelope);

/// A new sealer's salt: 64 random bits (libsodium's generator).
std::uint64_t random_salt();

/// Seals `message` in place: its first `clear_bytes` stay as written, the body after them
/// is encrypted if `encrypt`, and the tag is written into its last kTagBytes.
void seal_in_place(std::span<std::uint8_t> message, std::size_t clear_bytes, const Nonce& nonce,
                   const TrafficKey& key, bool encrypt);

/// Opens a message sealed that way: its body if the tag verifies, else nullopt. An
/// encrypted body is decrypted into `plaintext` (at least the body's size; it may be the
/// body's own bytes); a body in clear is returned where it lies. Never throws.
std::optional<std::span<const std::uint8_t>> open_sealed(std::span<const std::uint8_t> message,
                                                         std::size_t clear_bytes,
                                                         const Nonce& nonce, const TrafficKey& key,
                                                         bool encrypted,
                                                         std::span<std::uint8_t> plaintext);

}  // namespace cohaptic::wire
