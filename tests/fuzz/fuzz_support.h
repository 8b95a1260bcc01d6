// What the fuzz targets (tests/fuzz/fuzz_*.cpp) share: one input split into several
// messages, payloads sealed as a peer holding the keys would seal them, a scratch file for
// readers that take a path, and the check that turns a broken property into a finding.
//
// Sealing is the one place here that knows how the wire protects messages (protocol 3:
// envelope, XChaCha20-Poly1305 under the sender's traffic key, proto/wire/aead.h): a target
// gets past the tag check only with inputs it sealed itself, so each piece of an input says
// whether to seal it (the parser behind the check is fuzzed) or to send it as it is (the
// check itself is). The payload is sealed byte for byte as given, parsed or not; the
// envelope's sender and sequence are taken from the payload's header when it parses (so
// that a sealed message from a real peer passes), else 0. When the wire's sealing changes,
// sealed_datagram() and sealed_frame() change with it, and the seed corpora (unsealed
// payloads) stay valid.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string_view>
#include <vector>

#include "proto/wire/frame_codec.h"
#include "proto/wire/session_key.h"

namespace cohaptic::fuzz {

/// One message of an input: `kind` (a byte the target interprets, e.g. bit 0 = seal it)
/// and its bytes.
struct Piece {
  std::uint8_t kind = 0;
  std::span<const std::uint8_t> bytes;
};

/// An input read as pieces [u8 kind][u16 little-endian length][bytes]...; a piece whose
/// length runs past the end takes what is left, and a trailing kind byte alone is a piece
/// with no bytes. Every input splits; none is refused.
std::vector<Piece> split_pieces(std::span<const std::uint8_t> input);
/// Appends a piece in that layout (seeds; at most 65535 bytes).
void append_piece(std::vector<std::uint8_t>& input, std::uint8_t kind,
                  std::span<const std::uint8_t> bytes);

/// The session key of the fuzzed session, and the traffic key a peer seals `sender`'s
/// messages with (traffic_keys.h): its own for a participant and for the joining sender;
/// the server's (sender 0) are sealed with participant 0's key, as the server seals what
/// it sends the client in slot 0. The reference may be overwritten by the next call for
/// senders above 7 (other than the joining sender).
const wire::SessionKey& fuzz_session_key();
const wire::TrafficKey& fuzz_key(std::uint32_t sender);
/// The salt of every sealer the targets play: one sealer per direction and socket.
constexpr std::uint64_t kFuzzSalt = 0x0123'4567'89ab'cdefull;
/// The challenge of the server's greeting the control-frame target plays the client of.
const wire::Challenge& fuzz_challenge();

struct SealOptions {
  bool encrypt = true;     ///< false: in clear, authenticated only (--no-encryption)
  bool wrong_key = false;  ///< sealed with the next sender's key: another participant forging
};
/// `payload` as a datagram its header's sender sends.
std::vector<std::uint8_t> sealed_datagram(std::span<const std::uint8_t> payload,
                                          SealOptions options = {});
/// `payload` as one control frame (length, envelope, body, tag) its header's sender sends.
std::vector<std::uint8_t> sealed_frame(std::span<const std::uint8_t> payload,
                                       SealOptions options = {});

/// A file of this process holding exactly `bytes` (rewritten on every call), for readers
/// that take a path. `extension` e.g. ".mcap".
std::filesystem::path scratch_file(std::span<const std::uint8_t> bytes, std::string_view extension);

/// Unless `condition`, prints `property` and aborts: the fuzzer keeps the input as a crash.
void require(bool condition, const char* property);

}  // namespace cohaptic::fuzz
