// Framing of the TCP control channel: each Control message travels as
//   [u32 little-endian payload length][payload: serialized Control][32-byte tag]
// where the tag (authenticated.h) covers the 4 length bytes and the payload.
//
// FrameReader reassembles frames from a byte stream fed in arbitrary chunks and yields
// verified Control messages. A declared length above its limit, a bad tag, an unparsable
// payload, a protocol version other than kProtocolVersion, a frame without a body, or a
// sequence number not above the previous frame's (Header.sequence is strictly increasing
// per channel) throws FrameError: the stream cannot be trusted any more, so the error is
// sticky (every later next() throws it again) and the caller should close the connection.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "cohaptic/messages.pb.h"
#include "common/util/error.h"
#include "proto/wire/authenticated.h"
#include "proto/wire/session_key.h"

namespace cohaptic::wire {

constexpr std::size_t kFrameLengthBytes = 4;
constexpr std::size_t kFrameOverheadBytes = kFrameLengthBytes + kTagBytes;
constexpr std::size_t kDefaultMaxFrameBytes = std::size_t{64} << 20;  ///< payload limit: 64 MiB

class FrameError : public cohaptic::Error {
 public:
  using cohaptic::Error::Error;
};

/// The frame of `control`. Throws cohaptic::Error if the payload exceeds 2^32 - 1 bytes.
std::vector<std::uint8_t> encode_frame(const Control& control, const SessionKey& key);

class FrameReader {
 public:
  /// `max_payload_bytes`: the largest payload accepted (at most INT_MAX, protobuf's limit).
  explicit FrameReader(const SessionKey& key, std::size_t max_payload_bytes = kDefaultMaxFrameBytes);

  /// Appends received bytes (any amount, including none).
  void feed(std::span<const std::uint8_t> bytes);
  /// The next complete, verified frame's message, or nullopt if more bytes are needed.
  /// Throws FrameError as described above.
  std::optional<Control> next();

  /// Bytes received but not yet consumed as frames.
  std::size_t buffered() const { return buffer_.size() - begin_; }

 private:
  [[noreturn]] void fail(std::string what);

  SessionKey key_;
  std::size_t max_payload_;
  std::vector<std::uint8_t> buffer_;
  std::size_t begin_ = 0;  ///< start of the first unconsumed byte in buffer_
  std::optional<std::uint64_t> last_sequence_;
  std::optional<std::string> error_;
};

}  // namespace cohaptic::wire
