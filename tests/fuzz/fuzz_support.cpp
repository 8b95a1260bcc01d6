#include "tests/fuzz/fuzz_support.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>

#include "cohaptic/messages.pb.h"
#include "proto/wire/aead.h"
#include "proto/wire/envelope.h"
#include "proto/wire/header.h"
#include "proto/wire/traffic_keys.h"

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

void append_piece(std::vector<std::uint8_t>& input, std::uint8_t kind,
                  std::span<const std::uint8_t> bytes) {
  require(bytes.size() <= 0xffff, "a seed piece fits a 16-bit length");
  input.push_back(kind);
  input.push_back(static_cast<std::uint8_t>(bytes.size()));
  input.push_back(static_cast<std::uint8_t>(bytes.size() >> 8));
  input.insert(input.end(), bytes.begin(), bytes.end());
}

const wire::SessionKey& fuzz_session_key() {
  static const wire::SessionKey key = [] {
    wire::SessionKey k;
    for (std::size_t i = 0; i < k.bytes.size(); ++i)
      k.bytes[i] = static_cast<std::uint8_t>(0xa5 ^ (7 * i));
    return k;
  }();
  return key;
}

const wire::TrafficKey& fuzz_key(std::uint32_t sender) {
  // The keys of the first few senders and the joining sender are derived once: a fuzz run
  // seals millions of messages, nearly all from them. Any other sender's key is derived
  // into one scratch key, valid until the next call.
  constexpr std::uint32_t kCached = 8;
  static std::map<std::uint32_t, wire::TrafficKey> cached;
  static wire::TrafficKey scratch;
  const std::uint32_t owner = sender == wire::kServerSender ? wire::sender_of_slot(0) : sender;
  if (owner >= kCached && owner != wire::kJoiningSender)
    return scratch = wire::traffic_key(fuzz_session_key(), owner);
  auto found = cached.find(owner);
  if (found == cached.end())
    found = cached.emplace(owner, wire::traffic_key(fuzz_session_key(), owner)).first;
  return found->second;
}

const wire::Challenge& fuzz_challenge() {
  static const wire::Challenge challenge = [] {
    wire::Challenge c;
    for (std::size_t i = 0; i < c.size(); ++i) c[i] = static_cast<std::uint8_t>(0x3c + 11 * i);
    return c;
  }();
  return challenge;
}

namespace {

// Seals out[clear_bytes, end - tag) in place, behind an envelope at out[envelope_at] naming
// the payload's own sender and sequence.
template <class Message>
void seal_payload(std::vector<std::uint8_t>& out, std::size_t envelope_at,
                  std::span<const std::uint8_t> payload, wire::Channel channel,
                  SealOptions options) {
  Message parsed;
  const bool parses = parsed.ParseFromArray(payload.data(), static_cast<int>(payload.size()));
  const std::uint32_t sender = parses ? parsed.header().sender() : wire::kServerSender;
  const wire::Envelope envelope{static_cast<std::uint8_t>(wire::kProtocolVersion),
                                options.encrypt ? wire::kEncryptedFlag : std::uint8_t{0}, sender,
                                kFuzzSalt, parses ? parsed.header().sequence() : 0};
  wire::write_envelope(envelope, out.data() + envelope_at);
  std::copy(payload.begin(), payload.end(),
            out.begin() + static_cast<std::ptrdiff_t>(envelope_at + wire::kEnvelopeBytes));
  wire::seal_in_place(out, envelope_at + wire::kEnvelopeBytes, wire::make_nonce(channel, envelope),
                      fuzz_key(options.wrong_key ? sender + 2 : sender), options.encrypt);
}

}  // namespace

std::vector<std::uint8_t> sealed_datagram(std::span<const std::uint8_t> payload,
                                          SealOptions options) {
  std::vector<std::uint8_t> out(wire::kDatagramOverheadBytes + payload.size());
  seal_payload<wire::Datagram>(out, 0, payload, wire::Channel::datagram, options);
  return out;
}

std::vector<std::uint8_t> sealed_frame(std::span<const std::uint8_t> payload, SealOptions options) {
  std::vector<std::uint8_t> out(wire::kFrameOverheadBytes + payload.size());
  wire::write_le(payload.size(), wire::kFrameLengthBytes, out.data());
  seal_payload<wire::Control>(out, wire::kFrameLengthBytes, payload, wire::Channel::frame, options);
  return out;
}

namespace {

// The process's own directory under the temporary directory, removed at exit.
struct ScratchDirectory {
  std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("cohaptic-fuzz-" + std::to_string(::getpid()));
  ScratchDirectory() { std::filesystem::create_directories(path); }
  ~ScratchDirectory() {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
};

}  // namespace

std::filesystem::path scratch_file(std::span<const std::uint8_t> bytes,
                                   std::string_view extension) {
  static const ScratchDirectory directory;
  std::filesystem::path file = directory.path / "input";
  file += extension;
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
  require(out.good(), "the scratch file is written");
  return file;
}

void require(bool condition, const char* property) {
  if (condition) return;
  std::fprintf(stderr, "fuzz: property violated: %s\n", property);
  std::abort();
}

}  // namespace cohaptic::fuzz
