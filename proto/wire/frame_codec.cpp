#include "proto/wire/frame_codec.h"

#include <algorithm>
#include <climits>

#include "proto/wire/header.h"
#include "proto/wire/sodium_ready.h"

namespace cohaptic::wire {
namespace {

std::uint32_t read_u32_le(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
         static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
}

void write_u32_le(std::uint32_t v, std::uint8_t* p) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}

}  // namespace

std::vector<std::uint8_t> encode_frame(const Control& control, const SessionKey& key) {
  const std::size_t payload = control.ByteSizeLong();
  if (payload > UINT32_MAX)
    throw cohaptic::Error(fmt::format("control frame: a payload of {} bytes does not fit a 32-bit length", payload));
  std::vector<std::uint8_t> frame(kFrameLengthBytes + payload + kTagBytes);
  write_u32_le(static_cast<std::uint32_t>(payload), frame.data());
  control.SerializeWithCachedSizesToArray(frame.data() + kFrameLengthBytes);  // sizes cached by ByteSizeLong()
  const auto tag = authentication_tag(std::span(frame.data(), kFrameLengthBytes + payload), key);
  std::copy(tag.begin(), tag.end(), frame.end() - static_cast<std::ptrdiff_t>(kTagBytes));
  return frame;
}

FrameReader::FrameReader(const SessionKey& key, std::size_t max_payload_bytes)
    : key_(key), max_payload_(max_payload_bytes) {
  ensure_sodium();
  if (max_payload_bytes > static_cast<std::size_t>(INT_MAX))
    throw cohaptic::Error(fmt::format("FrameReader: a limit of {} bytes exceeds protobuf's {}", max_payload_bytes, INT_MAX));
}

void FrameReader::feed(std::span<const std::uint8_t> bytes) {
  // Drop consumed bytes once they are at least half the buffer: amortised O(1) per byte.
  if (begin_ > 0 && begin_ >= buffer_.size() / 2) {
    buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(begin_));
    begin_ = 0;
  }
  buffer_.insert(buffer_.end(), bytes.begin(), bytes.end());
}

void FrameReader::fail(std::string what) {
  error_ = "control frame: " + std::move(what);
  throw FrameError(*error_);
}

std::optional<Control> FrameReader::next() {
  if (error_) throw FrameError(*error_);
  if (buffered() < kFrameLengthBytes) return std::nullopt;
  const std::uint8_t* frame = buffer_.data() + begin_;
  const std::uint32_t length = read_u32_le(frame);
  if (length > max_payload_)
    fail(fmt::format("declared payload length {} exceeds the limit of {} bytes", length, max_payload_));
  const std::size_t signed_bytes = kFrameLengthBytes + length;
  if (buffered() < signed_bytes + kTagBytes) return std::nullopt;
  if (!verify_tag(std::span(frame, signed_bytes), std::span(frame + signed_bytes, kTagBytes), key_))
    fail(fmt::format("bad authentication tag on a frame of {} payload bytes (wrong key or corrupted)", length));
  Control control;
  if (!control.ParseFromArray(frame + kFrameLengthBytes, static_cast<int>(length)))
    fail(fmt::format("the {}-byte payload is not a Control message", length));
  begin_ += signed_bytes + kTagBytes;
  const Header& header = control.header();
  if (header.protocol_version() != kProtocolVersion)
    fail(fmt::format("protocol version {}, expected {}", header.protocol_version(), kProtocolVersion));
  if (control.body_case() == Control::BODY_NOT_SET) fail("a frame without a body");
  if (last_sequence_ && header.sequence() <= *last_sequence_)
    fail(fmt::format("sequence {} is not above the previous frame's {}", header.sequence(), *last_sequence_));
  last_sequence_ = header.sequence();
  if (begin_ == buffer_.size()) {
    buffer_.clear();
    begin_ = 0;
  }
  return control;
}

}  // namespace cohaptic::wire
