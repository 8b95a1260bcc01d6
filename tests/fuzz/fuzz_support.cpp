#include "tests/fuzz/fuzz_support.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>

#include "proto/wire/authenticated.h"
#include "proto/wire/frame_codec.h"

namespace cohaptic::fuzz {

std::vector<Piece> split_pieces(std::span<const std::uint8_t> input) {
  std::vector<Piece> pieces;
  std::size_t at = 0;
  while (at < input.size()) {
    Piece piece;
    piece.kind = input[at++];
    std::size_t length = 0;
    if (at + 2 <= input.size()) length = input[at] | std::size_t{input[at + 1]} << 8;
    at = std::min(at + 2, input.size());
    length = std::min(length, input.size() - at);
    piece.bytes = input.subspan(at, length);
    at += length;
    pieces.push_back(piece);
  }
  return pieces;
}

void append_piece(std::vector<std::uint8_t>& input, std::uint8_t kind, std::span<const std::uint8_t> bytes) {
  require(bytes.size() <= 0xffff, "a seed piece fits a 16-bit length");
  input.push_back(kind);
  input.push_back(static_cast<std::uint8_t>(bytes.size()));
  input.push_back(static_cast<std::uint8_t>(bytes.size() >> 8));
  input.insert(input.end(), bytes.begin(), bytes.end());
}

const wire::SessionKey& fuzz_key() {
  static const wire::SessionKey key = [] {
    wire::SessionKey k;
    for (std::size_t i = 0; i < k.bytes.size(); ++i) k.bytes[i] = static_cast<std::uint8_t>(0xa5 ^ (7 * i));
    return k;
  }();
  return key;
}

std::vector<std::uint8_t> sealed_datagram(std::span<const std::uint8_t> payload) { return wire::seal(payload, fuzz_key()); }

std::vector<std::uint8_t> sealed_frame(std::span<const std::uint8_t> payload) {
  std::vector<std::uint8_t> signed_part(wire::kFrameLengthBytes);
  for (std::size_t i = 0; i < wire::kFrameLengthBytes; ++i) signed_part[i] = static_cast<std::uint8_t>(payload.size() >> (8 * i));
  signed_part.insert(signed_part.end(), payload.begin(), payload.end());
  return wire::seal(signed_part, fuzz_key());
}

namespace {

// The process's own directory under the temporary directory, removed at exit.
struct ScratchDirectory {
  std::filesystem::path path = std::filesystem::temp_directory_path() / ("cohaptic-fuzz-" + std::to_string(::getpid()));
  ScratchDirectory() { std::filesystem::create_directories(path); }
  ~ScratchDirectory() {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
};

}  // namespace

std::filesystem::path scratch_file(std::span<const std::uint8_t> bytes, std::string_view extension) {
  static const ScratchDirectory directory;
  std::filesystem::path file = directory.path / "input";
  file += extension;
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  require(out.good(), "the scratch file is written");
  return file;
}

void require(bool condition, const char* property) {
  if (condition) return;
  std::fprintf(stderr, "fuzz: property violated: %s\n", property);
  std::abort();
}

}  // namespace cohaptic::fuzz
