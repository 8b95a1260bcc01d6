// Key files: the session key (the server's secret, from which every participant's traffic
// key is derived, traffic_keys.h) and participant key files (one slot's traffic key).
//
// On disk:
//   - a session key file is 64 hexadecimal characters (upper or lower case), optionally
//     surrounded or interleaved by whitespace and newlines; nothing else;
//   - a participant key file is a line `participant K` (K the slot, from 0), then the 64
//     hexadecimal characters of that slot's traffic key.
// Both are created with mode 0600, and a key file that its group or others may read,
// write or execute (any bit of 077) is refused: a key someone else can read is no secret.
// Keys are wiped from memory when their objects die, and never logged (to_hex is for key
// files and tests). Without a key file both sides fall back to development_key(), which is
// public: it protects nothing against an attacker, and callers must log a warning.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <variant>

namespace cohaptic::wire {

/// 256 bits of secret, wiped when destroyed.
struct SecretBytes {
  std::array<std::uint8_t, 32> bytes{};
  SecretBytes() = default;
  SecretBytes(const SecretBytes&) = default;
  SecretBytes& operator=(const SecretBytes&) = default;
  ~SecretBytes();
};

/// The session's secret. It seals no traffic itself: traffic_keys.h derives from it.
struct SessionKey : SecretBytes {};

/// The key that seals one sender's traffic (traffic_keys.h): a participant's, or the joining key.
struct TrafficKey : SecretBytes {};

/// What a participant key file holds.
struct ParticipantKey {
  std::uint32_t slot = 0;
  TrafficKey key;
};

/// Reads a key file of either kind. Throws cohaptic::Error naming the file and the problem,
/// e.g. "key.txt: expected 64 hexadecimal characters, found 12", or a mode that lets others
/// in ("... mode 0644: others may read it; chmod 600 key.txt").
std::variant<SessionKey, ParticipantKey> load_key_file(const std::filesystem::path& file);

/// Reads a session key file; a participant key file is refused, naming its slot.
SessionKey load_session_key(const std::filesystem::path& file);

/// The fixed, publicly known development key: the 32 ASCII bytes
/// "cohaptic-development-key-public!" (hex
/// 636f6861707469632d646576656c6f706d656e742d6b65792d7075626c696321). Anyone can forge and read
/// traffic with it; use it only on a trusted network, and warn.
SessionKey development_key();

/// Creates `file` (which must not exist) with mode 0600 holding a new random session key
/// as 64 lowercase hex characters and a newline. Throws cohaptic::Error naming the file on failure.
void write_session_key(const std::filesystem::path& file);

/// Creates `file` (which must not exist) with mode 0600 holding the participant key of
/// `slot`, derived from `session`. Throws cohaptic::Error naming the file on failure.
void write_participant_key(const std::filesystem::path& file, const SessionKey& session,
                           std::uint32_t slot);

/// The key as 64 lowercase hex characters (for key files and tests; never log it).
std::string to_hex(const SecretBytes& key);

}  // namespace cohaptic::wire
