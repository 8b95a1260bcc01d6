// The envelope: the clear bytes in front of every sealed datagram and frame (protocol 3).
//
//   offset  size  field
//        0     1  protocol version (kProtocolVersion)
//        1     1  flags: bit 0 set = the body is encrypted; the other bits are 0
//        2     4  sender (little-endian): 0 the server, k + 1 slot k, kJoiningSender
//        6     8  salt (little-endian): drawn at random by each sealer when it is made
//       14     8  sequence (little-endian): the sealer's, from 1, one more per message
//
// The receiver reads the sender to pick the key, and the AEAD's nonce is made of salt,
// sender, channel and sequence (aead.h). The envelope travels in clear but is authenticated
// (associated data). Its sender and sequence repeat the sealed Header's, and must agree.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

namespace cohaptic::wire {

constexpr std::size_t kEnvelopeBytes = 22;
constexpr std::uint8_t kEncryptedFlag = 0x01;

struct Envelope {
  std::uint8_t version = 0;
  std::uint8_t flags = 0;
  std::uint32_t sender = 0;
  std::uint64_t salt = 0;
  std::uint64_t sequence = 0;

  bool encrypted() const { return (flags & kEncryptedFlag) != 0; }
  /// A version and flags this program understands.
  bool known_format() const;
};

/// Writes `envelope` to out[0, kEnvelopeBytes).
void write_envelope(const Envelope& envelope, std::uint8_t* out);
/// Reads the envelope at the start of `bytes`; nullopt if they are fewer than kEnvelopeBytes.
std::optional<Envelope> read_envelope(std::span<const std::uint8_t> bytes);

/// Little-endian integers, as the envelope and the frame length are written.
void write_le(std::uint64_t value, std::size_t bytes, std::uint8_t* out);
std::uint64_t read_le(const std::uint8_t* in, std::size_t bytes);

}  // namespace cohaptic::wire
