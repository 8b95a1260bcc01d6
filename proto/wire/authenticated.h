// Authentication of wire messages with the session key: a payload is followed by a
// 32-byte HMAC-SHA-512-256 tag (libsodium crypto_auth) computed over the payload, and a
// receiver accepts it only if the tag verifies (constant-time comparison).
//
// Authentication only: payloads travel in clear. A verified tag proves the sender knows
// the session key, not that the message is fresh (replay protection: datagram_codec.h).
// kMaxDatagramBytes bounds a whole UDP datagram, tag included, below a typical path MTU.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "proto/wire/session_key.h"

namespace cohaptic::wire {

constexpr std::size_t kTagBytes = 32;
constexpr std::size_t kMaxDatagramBytes = 1400;

/// The tag of `message` under `key`.
std::array<std::uint8_t, kTagBytes> authentication_tag(std::span<const std::uint8_t> message, const SessionKey& key);

/// True if `tag` is the tag of `message` under `key` (constant time in the tag).
bool verify_tag(std::span<const std::uint8_t> message, std::span<const std::uint8_t> tag, const SessionKey& key);

/// `payload` followed by its tag.
std::vector<std::uint8_t> seal(std::span<const std::uint8_t> payload, const SessionKey& key);

/// The payload part of `packet` (a view into it) if its trailing tag verifies; nullopt if
/// the packet is shorter than a tag or the tag is wrong. Never throws.
std::optional<std::span<const std::uint8_t>> open(std::span<const std::uint8_t> packet, const SessionKey& key);

}  // namespace cohaptic::wire
