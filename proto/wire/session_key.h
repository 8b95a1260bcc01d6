// SessionKey: the 256-bit secret shared by a server and its clients, used to authenticate
// every UDP datagram and TCP frame (HMAC-SHA-512-256, see authenticated.h).
//
// On disk a key is 64 hexadecimal characters (upper or lower case), optionally surrounded
// or interleaved by whitespace and newlines; nothing else. Key files are created with mode
// 0600. Without a key file both sides fall back to development_key(), which is public:
// it authenticates nothing against an attacker and callers must log a warning.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>

namespace cohaptic::wire {

struct SessionKey {
  std::array<std::uint8_t, 32> bytes{};
};

/// Reads a key file. Throws cohaptic::Error naming the file and the problem, e.g.
/// "key.txt: expected 64 hexadecimal characters, found 12".
SessionKey load_session_key(const std::filesystem::path& file);

/// The fixed, publicly known development key: the 32 ASCII bytes
/// "cohaptic-development-key-public!" (hex 636f6861707469632d646576656c6f706d656e742d6b65792d7075626c696321).
/// Anyone can forge traffic with it; use it only on a trusted network, and warn.
SessionKey development_key();

/// Creates `file` (which must not exist) with mode 0600 holding a new random key as 64
/// lowercase hex characters and a newline. Throws cohaptic::Error naming the file on failure.
void write_session_key(const std::filesystem::path& file);

/// The key as 64 lowercase hex characters (for key files and tests; never log it).
std::string to_hex(const SessionKey& key);

}  // namespace cohaptic::wire
