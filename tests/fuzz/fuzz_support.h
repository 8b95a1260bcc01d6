// What the fuzz targets (tests/fuzz/fuzz_*.cpp) share: one input split into several
// messages, payloads sealed as a peer holding the session key would seal them, a scratch
// file for readers that take a path, and the check that turns a broken property into a
// finding.
//
// Sealing is the one place here that knows how the wire authenticates: a target gets past
// the tag check only with inputs it sealed itself, so each piece of an input says whether
// to seal it (the parser behind the check is fuzzed) or to send it as it is (the check
// itself is). When the wire's sealing changes, sealed_datagram() and sealed_frame() change
// with it, and the seed corpora (unsealed payloads) stay valid.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string_view>
#include <vector>

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
void append_piece(std::vector<std::uint8_t>& input, std::uint8_t kind, std::span<const std::uint8_t> bytes);

/// The key every target seals and verifies with.
const wire::SessionKey& fuzz_key();
/// `payload` as a datagram a holder of fuzz_key() sends.
std::vector<std::uint8_t> sealed_datagram(std::span<const std::uint8_t> payload);
/// `payload` as one control frame (length, payload, tag) a holder of fuzz_key() sends.
std::vector<std::uint8_t> sealed_frame(std::span<const std::uint8_t> payload);

/// A file of this process holding exactly `bytes` (rewritten on every call), for readers
/// that take a path. `extension` e.g. ".mcap".
std::filesystem::path scratch_file(std::span<const std::uint8_t> bytes, std::string_view extension);

/// Unless `condition`, prints `property` and aborts: the fuzzer keeps the input as a crash.
void require(bool condition, const char* property);

}  // namespace cohaptic::fuzz
