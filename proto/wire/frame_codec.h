// Framing of the TCP control channel (protocol 3). Each Control message travels as
//   [u32 little-endian body length][envelope (envelope.h)][body: serialized Control][16-byte tag]
// sealed under the sender's traffic key (aead.h); length and envelope are the clear part.
// The server opens every connection with a greeting before any frame:
//   "cohaptic" (8 ASCII bytes) | protocol version (1 byte) | challenge (16 random bytes)
// and the client's Join must carry that challenge, so that a Join recorded on one
// connection is refused on another (the Welcome likewise echoes the client's challenge).
//
// FrameReader reassembles frames from a byte stream fed in arbitrary chunks and yields
// verified Control messages; on the client's side (expect_greeting) it first yields the
// greeting as a Control whose body is a Hello (no header: it is not sealed). A frame that
// fails a check throws FrameError, which names the Rejection: a declared length above the
// limit (oversized); a greeting or envelope of another protocol version or unknown flags
// (bad_version); a frame in clear when encryption is required (cleartext); a sender the
// reader has no key for (unknown_sender); a tag that does not verify, or a sealed header
// whose sender or sequence differ from the envelope's (bad_tag); a body that does not
// parse (truncated); a header version other than kProtocolVersion (bad_version); no body
// (empty); a frame sealed by another sealer than the stream's first frame (its salt), or a
// sequence not above the previous frame's (replayed). The stream cannot be trusted any
// more, so the error is sticky (every later next() throws it again) and the caller should
// close the connection.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "cohaptic/messages.pb.h"
#include "common/util/error.h"
#include "proto/wire/aead.h"
#include "proto/wire/datagram_codec.h"
#include "proto/wire/rejection.h"
#include "proto/wire/session_key.h"

namespace cohaptic::wire {

constexpr std::size_t kFrameLengthBytes = 4;
constexpr std::size_t kFrameClearBytes = kFrameLengthBytes + kEnvelopeBytes;
constexpr std::size_t kFrameOverheadBytes = kFrameClearBytes + kTagBytes;
constexpr std::size_t kDefaultMaxFrameBytes = std::size_t{64} << 20;  ///< body limit: 64 MiB

constexpr std::size_t kChallengeBytes = 16;
using Challenge = std::array<std::uint8_t, kChallengeBytes>;
constexpr std::size_t kGreetingBytes = 8 + 1 + kChallengeBytes;

class FrameError : public cohaptic::Error {
 public:
  FrameError(Rejection reason, const std::string& what) : cohaptic::Error(what), reason_(reason) {}
  Rejection reason() const { return reason_; }

 private:
  Rejection reason_;
};

/// The sealed frame of `control`, whose header gives the envelope's sender and sequence.
/// Throws cohaptic::Error if the body exceeds 2^32 - 1 bytes.
std::vector<std::uint8_t> encode_frame(const Control& control, const SealWith& seal);

/// The server's greeting with `challenge`, and a fresh random challenge.
std::vector<std::uint8_t> encode_greeting(const Challenge& challenge);
Challenge random_challenge();
/// Whether `bytes` (a protobuf bytes field) is `challenge`, in constant time.
bool is_challenge(const std::string& bytes, const Challenge& challenge);

struct FrameReaderOptions {
  bool expect_greeting =
      false;  ///< the client's side: the stream starts with the server's greeting
  bool allow_cleartext = false;  ///< accept frames sent in clear (authenticated, not encrypted)
  std::size_t max_body_bytes = kDefaultMaxFrameBytes;  ///< at most INT_MAX, protobuf's limit
};

class FrameReader {
 public:
  /// The key of `sender`'s frames, or null if this stream accepts no frames from it. Asked
  /// once per frame, so the answer may change within the stream (a key after the join).
  using KeyFor = std::function<const TrafficKey*(std::uint32_t sender)>;

  explicit FrameReader(KeyFor key_for, FrameReaderOptions options = {});

  /// Appends received bytes (any amount, including none).
  void feed(std::span<const std::uint8_t> bytes);
  /// The next complete, verified frame's message (or the greeting's Hello), or nullopt if
  /// more bytes are needed. Throws FrameError as described above.
  std::optional<Control> next();
  /// The largest body the frames from now on may declare (FrameReaderOptions::max_body_bytes).
  void set_max_body_bytes(std::size_t bytes);
  /// The envelope sender of the frame next() returned last: whose key opened it.
  std::uint32_t last_sender() const { return last_sender_; }

  /// Bytes received but not yet consumed as frames.
  std::size_t buffered() const { return buffer_.size() - begin_; }

 private:
  [[noreturn]] void fail(Rejection reason, std::string what);
  std::optional<Control> next_greeting();
  void consume(std::size_t bytes);

  KeyFor key_for_;
  FrameReaderOptions options_;
  std::vector<std::uint8_t> buffer_;
  std::size_t begin_ = 0;  ///< start of the first unconsumed byte in buffer_
  bool greeted_ = false;
  std::optional<std::uint64_t> salt_;  ///< the stream's sealer, from its first frame
  std::optional<std::uint64_t> last_sequence_;
  std::uint32_t last_sender_ = 0;
  std::optional<FrameError> error_;
};

}  // namespace cohaptic::wire
