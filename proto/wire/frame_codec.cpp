#include "proto/wire/frame_codec.h"

#include <sodium.h>

#include <algorithm>
#include <climits>
#include <string_view>

#include "proto/wire/header.h"
#include "proto/wire/sodium_ready.h"

namespace cohaptic::wire {
namespace {

constexpr std::string_view kGreetingMagic = "cohaptic";

}  // namespace

std::vector<std::uint8_t> encode_frame(const Control& control, const SealWith& seal) {
  const std::size_t body = control.ByteSizeLong();
  if (body > UINT32_MAX)
    throw cohaptic::Error(
        fmt::format("control frame: a body of {} bytes does not fit a 32-bit length", body));
  std::vector<std::uint8_t> frame(kFrameOverheadBytes + body);
  write_le(body, kFrameLengthBytes, frame.data());
  const Envelope envelope{kProtocolVersion, seal.encrypt ? kEncryptedFlag : std::uint8_t{0},
                          control.header().sender(), seal.salt, control.header().sequence()};
  write_envelope(envelope, frame.data() + kFrameLengthBytes);
  control.SerializeWithCachedSizesToArray(frame.data() +
                                          kFrameClearBytes);  // sizes cached by ByteSizeLong()
  seal_in_place(frame, kFrameClearBytes, make_nonce(Channel::frame, envelope), seal.key,
                seal.encrypt);
  return frame;
}

std::vector<std::uint8_t> encode_greeting(const Challenge& challenge) {
  std::vector<std::uint8_t> greeting(kGreetingMagic.begin(), kGreetingMagic.end());
  greeting.push_back(static_cast<std::uint8_t>(kProtocolVersion));
  greeting.insert(greeting.end(), challenge.begin(), challenge.end());
  return greeting;
}

Challenge random_challenge() {
  ensure_sodium();
  Challenge challenge;
  randombytes_buf(challenge.data(), challenge.size());
  return challenge;
}

bool is_challenge(const std::string& bytes, const Challenge& challenge) {
  return bytes.size() == challenge.size() &&
         sodium_memcmp(bytes.data(), challenge.data(), challenge.size()) == 0;
}

FrameReader::FrameReader(KeyFor key_for, FrameReaderOptions options)
    : key_for_(std::move(key_for)), options_(options) {
  ensure_sodium();
  set_max_body_bytes(options.max_body_bytes);
}

void FrameReader::set_max_body_bytes(std::size_t bytes) {
  if (bytes > static_cast<std::size_t>(INT_MAX))
    throw cohaptic::Error(
        fmt::format("FrameReader: a limit of {} bytes exceeds protobuf's {}", bytes, INT_MAX));
  options_.max_body_bytes = bytes;
}

void FrameReader::feed(std::span<const std::uint8_t> bytes) {
  // Drop consumed bytes once they are at least half the buffer: amortised O(1) per byte.
  if (begin_ > 0 && begin_ >= buffer_.size() / 2) {
    buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(begin_));
    begin_ = 0;
  }
  buffer_.insert(buffer_.end(), bytes.begin(), bytes.end());
}

void FrameReader::fail(Rejection reason, std::string what) {
  error_.emplace(reason, "control frame: " + std::move(what));
  throw *error_;
}

void FrameReader::consume(std::size_t bytes) {
  begin_ += bytes;
  if (begin_ == buffer_.size()) {
    buffer_.clear();
    begin_ = 0;
  }
}

std::optional<Control> FrameReader::next_greeting() {
  if (buffered() < kGreetingBytes) return std::nullopt;
  const std::uint8_t* greeting = buffer_.data() + begin_;
  if (!std::equal(kGreetingMagic.begin(), kGreetingMagic.end(), greeting))
    fail(Rejection::bad_version,
         "the peer did not open with a cohaptic greeting (an older cohaptic, protocol 1 or 2, "
         "opens with nothing; or not cohaptic at all)");
  if (greeting[kGreetingMagic.size()] != kProtocolVersion)
    fail(Rejection::bad_version, fmt::format("the peer speaks protocol version {}, this program {}",
                                             greeting[kGreetingMagic.size()], kProtocolVersion));
  Control control;
  const std::uint8_t* challenge = greeting + kGreetingMagic.size() + 1;
  control.mutable_hello()->set_challenge(challenge, kChallengeBytes);
  consume(kGreetingBytes);
  greeted_ = true;
  last_sender_ = kServerSender;
  return control;
}

std::optional<Control> FrameReader::next() {
  if (error_) throw *error_;
  if (options_.expect_greeting && !greeted_) return next_greeting();
  if (buffered() < kFrameLengthBytes) return std::nullopt;
  std::uint8_t* frame = buffer_.data() + begin_;
  const std::uint64_t length = read_le(frame, kFrameLengthBytes);
  if (length > options_.max_body_bytes)
    fail(Rejection::oversized, fmt::format("declared body length {} exceeds the limit of {} bytes",
                                           length, options_.max_body_bytes));
  if (buffered() < kFrameClearBytes) return std::nullopt;
  const Envelope envelope = *read_envelope(std::span(frame + kFrameLengthBytes, kEnvelopeBytes));
  if (envelope.version != kProtocolVersion)
    fail(Rejection::bad_version,
         fmt::format("envelope version byte {}, expected protocol version {} (a protocol 1 or 2 "
                     "peer, an older cohaptic, sends no envelope)",
                     envelope.version, kProtocolVersion));
  if (!envelope.known_format())
    fail(Rejection::bad_version, fmt::format("unknown envelope flags 0x{:02x}", envelope.flags));
  if (!envelope.encrypted() && !options_.allow_cleartext)
    fail(Rejection::cleartext,
         "a frame in clear, and this side requires encryption (is the peer run with "
         "--no-encryption?)");
  const TrafficKey* key = key_for_(envelope.sender);
  if (!key)
    fail(Rejection::unknown_sender,
         fmt::format("a frame from sender {}, which this stream does not accept", envelope.sender));

  const std::size_t frame_bytes = kFrameOverheadBytes + static_cast<std::size_t>(length);
  if (buffered() < frame_bytes) return std::nullopt;
  std::uint8_t* body = frame + kFrameClearBytes;
  const auto opened = open_sealed(std::span(frame, frame_bytes), kFrameClearBytes,
                                  make_nonce(Channel::frame, envelope), *key, envelope.encrypted(),
                                  std::span(body, static_cast<std::size_t>(length)));
  if (!opened)
    fail(
        Rejection::bad_tag,
        fmt::format("bad authentication tag on a frame of {} body bytes from sender {} (wrong key, "
                    "another slot's key, or corrupted)",
                    length, envelope.sender));
  Control control;
  if (!control.ParseFromArray(opened->data(), static_cast<int>(opened->size())))
    fail(Rejection::truncated, fmt::format("the {}-byte body is not a Control message", length));
  consume(frame_bytes);
  const Header& header = control.header();
  if (header.protocol_version() != kProtocolVersion)
    fail(Rejection::bad_version, fmt::format("protocol version {}, expected {}",
                                             header.protocol_version(), kProtocolVersion));
  if (header.sender() != envelope.sender || header.sequence() != envelope.sequence)
    fail(Rejection::bad_tag,
         fmt::format(
             "the sealed header (sender {}, sequence {}) disagrees with the envelope (sender {}, "
             "sequence {})",
             header.sender(), header.sequence(), envelope.sender, envelope.sequence));
  if (control.body_case() == Control::BODY_NOT_SET)
    fail(Rejection::empty, "a frame without a body");
  if (salt_ && envelope.salt != *salt_)
    fail(Rejection::replayed,
         "a frame sealed by another sealer than this stream's (replayed from another connection?)");
  if (last_sequence_ && envelope.sequence <= *last_sequence_)
    fail(Rejection::replayed, fmt::format("sequence {} is not above the previous frame's {}",
                                          envelope.sequence, *last_sequence_));
  salt_ = envelope.salt;
  last_sequence_ = envelope.sequence;
  last_sender_ = envelope.sender;
  return control;
}

}  // namespace cohaptic::wire
