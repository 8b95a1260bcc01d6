#include "proto/wire/envelope.h"

#include "proto/wire/header.h"

namespace cohaptic::wire {

bool Envelope::known_format() const {
  return version == kProtocolVersion && (flags & ~kEncryptedFlag) == 0;
}

void write_le(std::uint64_t value, std::size_t bytes, std::uint8_t* out) {
  for (std::size_t i = 0; i < bytes; ++i) out[i] = static_cast<std::uint8_t>(value >> (8 * i));
}

std::uint64_t read_le(const std::uint8_t* in, std::size_t bytes) {
  std::uint64_t value = 0;
  for (std::size_t i = 0; i < bytes; ++i) value |= static_cast<std::uint64_t>(in[i]) << (8 * i);
  return value;
}

void write_envelope(const Envelope& envelope, std::uint8_t* out) {
  out[0] = envelope.version;
  out[1] = envelope.flags;
  write_le(envelope.sender, 4, out + 2);
  write_le(envelope.salt, 8, out + 6);
  write_le(envelope.sequence, 8, out + 14);
}

std::optional<Envelope> read_envelope(std::span<const std::uint8_t> bytes) {
  if (bytes.size() < kEnvelopeBytes) return std::nullopt;
  Envelope envelope;
  envelope.version = bytes[0];
  envelope.flags = bytes[1];
  envelope.sender = static_cast<std::uint32_t>(read_le(bytes.data() + 2, 4));
  envelope.salt = read_le(bytes.data() + 6, 8);
  envelope.sequence = read_le(bytes.data() + 14, 8);
  return envelope;
}

}  // namespace cohaptic::wire
