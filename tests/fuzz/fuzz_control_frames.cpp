// Fuzz target: the TCP control channel's framing and authentication
// (proto/wire/frame_codec.h), and the checks a client runs on what a frame carries.
//
// Input: pieces (fuzz_support.h) concatenated into one byte stream, as a client reads it
// from the server. Kind bit 0 set: the bytes are a Control payload this target frames and
// seals as its header's sender (fuzz_support.h), encrypted unless bit 7 is set too
// (then in clear, which the reader refuses: cleartext); clear: the bytes join the stream as
// they are (a lying length, a bad tag, half a frame). Bits 1-6 set how the stream is cut
// into reads (1 to 64 bytes per read). The stream starts with the server's greeting when
// the first piece is sealed; a first piece sent as it is takes the greeting's place.
// Three FrameReaders (expecting the greeting; holding the keys of the server, four
// participants and the joining sender) get the same stream: whole, byte by byte (streams
// up to 4 kB), and in those reads.
// Properties:
//   - each yields the same messages in the same order and stops with the same error (or
//     the same number of bytes still waiting): framing does not depend on how TCP cuts the
//     stream;
//   - an error is sticky: next() throws it again;
//   - the greeting, if read, is a Hello carrying a challenge of 16 bytes;
//   - a message yielded after it has our protocol version, a body, and a sequence number
//     above the previous one;
//   - the client's checks of a Welcome and its surface mesh, and the conversion of an IR
//     (proto/wire/ir_convert.h), plain or taken out of the stream's compressed IR blocks
//     (proto/wire/ir_stream.h, one reader for the stream), either accept or throw
//     cohaptic::Error: nothing else escapes.
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "client/welcome.h"
#include "proto/wire/frame_codec.h"
#include "proto/wire/header.h"
#include "proto/wire/ir_convert.h"
#include "proto/wire/ir_stream.h"
#include "proto/wire/surface_mesh_message.h"
#include "tests/fuzz/fuzz_support.h"

namespace {

using namespace cohaptic;
using fuzz::require;

// What a reader made of the stream.
struct Outcome {
  std::vector<wire::Control> messages;
  std::optional<std::string> error;
  std::size_t left_buffered = 0;
};

// Takes every frame the reader has ready; false once it has failed.
bool drain(wire::FrameReader& reader, Outcome& outcome) {
  try {
    while (std::optional<wire::Control> control = reader.next())
      outcome.messages.push_back(std::move(*control));
    return true;
  } catch (const wire::FrameError& error) {
    outcome.error = error.what();
    try {
      reader.next();
      require(false, "a failed reader fails again");
    } catch (const wire::FrameError& again) {
      require(outcome.error == again.what(), "a failed reader repeats its error");
    }
    return false;
  }
}

Outcome read_in_chunks(std::span<const std::uint8_t> stream,
                       const std::vector<std::size_t>& chunks) {
  const auto key_for = [](std::uint32_t sender) -> const wire::TrafficKey* {
    if (sender <= wire::sender_of_slot(3) || sender == wire::kJoiningSender)
      return &fuzz::fuzz_key(sender);
    return nullptr;
  };
  wire::FrameReader reader(key_for, {.expect_greeting = true});
  Outcome outcome;
  std::size_t at = 0;
  for (std::size_t i = 0; at < stream.size(); ++i) {
    const std::size_t n = std::min(chunks[i % chunks.size()], stream.size() - at);
    reader.feed(stream.subspan(at, n));
    at += n;
    if (!drain(reader, outcome)) return outcome;
  }
  outcome.left_buffered = reader.buffered();
  return outcome;
}

bool same(const Outcome& a, const Outcome& b) {
  if (a.messages.size() != b.messages.size() || a.error != b.error ||
      a.left_buffered != b.left_buffered)
    return false;
  for (std::size_t i = 0; i < a.messages.size(); ++i)
    if (a.messages[i].SerializeAsString() != b.messages[i].SerializeAsString()) return false;
  return true;
}

// What the client does with a frame's content before anything else sees it.
void check_content(const wire::Control& control, wire::IrStreamReader& ir_stream) {
  try {
    if (control.has_welcome()) {
      welcome_info(control.welcome());
      wire::from_wire(control.welcome().surface());
    } else if (control.has_ir()) {
      wire::from_wire(control.ir());
    } else if (control.has_compressed_ir()) {
      wire::from_wire(ir_stream.open(control.compressed_ir()));
    }
  } catch (const Error&) {
    // Refused with a message: what a hostile or broken peer should get.
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::vector<fuzz::Piece> pieces = fuzz::split_pieces({data, size});
  std::vector<std::uint8_t> stream;
  if (!pieces.empty() && (pieces.front().kind & 1))
    stream = wire::encode_greeting(fuzz::fuzz_challenge());
  std::vector<std::size_t> chunks;
  for (const fuzz::Piece& piece : pieces) {
    if (piece.kind & 1) {
      const std::vector<std::uint8_t> frame =
          fuzz::sealed_frame(piece.bytes, {.encrypt = (piece.kind & 0x80) == 0});
      stream.insert(stream.end(), frame.begin(), frame.end());
    } else {
      stream.insert(stream.end(), piece.bytes.begin(), piece.bytes.end());
    }
    chunks.push_back(std::size_t{(piece.kind >> 1) & 0x3fu} + 1);
  }
  if (chunks.empty()) chunks.push_back(1);

  const Outcome whole = read_in_chunks(stream, {std::max<std::size_t>(stream.size(), 1)});
  // Byte by byte costs a feed per byte: done for streams up to a few frames of tool-sized
  // messages, so that streams carrying an IR still run hundreds of times a second.
  constexpr std::size_t kByteByByteLimit = 4096;
  if (stream.size() <= kByteByByteLimit)
    require(same(whole, read_in_chunks(stream, {1})),
            "byte by byte reads the same frames as the whole stream");
  require(same(whole, read_in_chunks(stream, chunks)),
          "reads of any size read the same frames as the whole stream");

  std::optional<std::uint64_t> previous;
  wire::IrStreamReader ir_stream;
  for (std::size_t i = 0; i < whole.messages.size(); ++i) {
    const wire::Control& control = whole.messages[i];
    if (i == 0) {
      require(control.has_hello() && control.hello().challenge().size() == wire::kChallengeBytes,
              "the stream's first message is the greeting, with its challenge");
      continue;
    }
    require(control.header().protocol_version() == wire::kProtocolVersion,
            "a frame read has our version");
    require(control.body_case() != wire::Control::BODY_NOT_SET, "a frame read has a body");
    require(!previous || control.header().sequence() > *previous, "sequence numbers increase");
    previous = control.header().sequence();
    check_content(control, ir_stream);
  }
  return 0;
}
