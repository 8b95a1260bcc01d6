#include "proto/wire/datagram_codec.h"

#include <algorithm>
#include <array>

#include "common/util/error.h"
#include "proto/wire/sodium_ready.h"
#include "proto/wire/vec3_convert.h"

namespace cohaptic::wire {
namespace {

/// Size and envelope: the checks before a key is chosen.
std::optional<Rejection> envelope_rejection(std::span<const std::uint8_t> bytes,
                                            bool allow_cleartext, Envelope& out) {
  if (bytes.size() > kMaxDatagramBytes) return Rejection::oversized;
  if (bytes.size() < kDatagramOverheadBytes) return Rejection::truncated;
  out = *read_envelope(bytes);
  if (!out.known_format()) return Rejection::bad_version;
  if (!out.encrypted() && !allow_cleartext) return Rejection::cleartext;
  return std::nullopt;
}

/// Tag, parse and the sealed header: the checks that prove who sealed what.
std::optional<Rejection> open_and_parse(std::span<const std::uint8_t> bytes,
                                        const Envelope& envelope, const TrafficKey& key,
                                        Datagram& out) {
  std::array<std::uint8_t, kMaxDatagramBytes> plaintext;  // no heap: a datagram is small
  const auto body = open_sealed(bytes, kEnvelopeBytes, make_nonce(Channel::datagram, envelope), key,
                                envelope.encrypted(), plaintext);
  if (!body) return Rejection::bad_tag;
  if (!out.ParseFromArray(body->data(), static_cast<int>(body->size())))
    return Rejection::truncated;
  const Header& header = out.header();
  if (header.protocol_version() != kProtocolVersion) return Rejection::bad_version;
  if (header.sender() != envelope.sender || header.sequence() != envelope.sequence)
    return Rejection::bad_tag;
  return std::nullopt;
}

}  // namespace

void encode_datagram(const Datagram& datagram, const SealWith& seal,
                     std::vector<std::uint8_t>& out) {
  const std::size_t body = datagram.ByteSizeLong();
  if (body + kDatagramOverheadBytes > kMaxDatagramBytes)
    throw cohaptic::Error(fmt::format("datagram of {} bytes sealed exceeds the limit of {} bytes",
                                      body + kDatagramOverheadBytes, kMaxDatagramBytes));
  out.resize(body + kDatagramOverheadBytes);
  const Envelope envelope{kProtocolVersion, seal.encrypt ? kEncryptedFlag : std::uint8_t{0},
                          datagram.header().sender(), seal.salt, datagram.header().sequence()};
  write_envelope(envelope, out.data());
  datagram.SerializeWithCachedSizesToArray(out.data() +
                                           kEnvelopeBytes);  // sizes cached by ByteSizeLong()
  seal_in_place(out, kEnvelopeBytes, make_nonce(Channel::datagram, envelope), seal.key,
                seal.encrypt);
}

std::vector<std::uint8_t> encode_datagram(const Datagram& datagram, const SealWith& seal) {
  std::vector<std::uint8_t> out;
  encode_datagram(datagram, seal, out);
  return out;
}

std::optional<Rejection> body_rejection(const Datagram& datagram) {
  const auto clock = [](std::int64_t ns) { return ns >= 0 && ns < kMaxClockNs; };
  bool times_in_range = clock(datagram.header().sender_time_ns());
  switch (datagram.body_case()) {
    case Datagram::BODY_NOT_SET:
      return Rejection::empty;
    case Datagram::kTool:
      if (!is_finite(datagram.tool().position())) return Rejection::non_finite;
      times_in_range = times_in_range && clock(datagram.tool().sample_time_ns());
      break;
    case Datagram::kForce:
      if (!is_finite(datagram.force().force())) return Rejection::non_finite;
      times_in_range = times_in_range && clock(datagram.force().tool_time_ns());
      break;
    case Datagram::kKeepAlive:
      if (!std::isfinite(datagram.keep_alive().simulation_time())) return Rejection::non_finite;
      break;
    case Datagram::kPing:
      times_in_range = times_in_range && clock(datagram.ping().client_send_ns());
      break;
    case Datagram::kPong: {
      const ClockPong& pong = datagram.pong();
      times_in_range = times_in_range && clock(pong.client_send_ns()) &&
                       clock(pong.server_receive_ns()) && clock(pong.server_send_ns());
      break;
    }
  }
  if (!times_in_range) return Rejection::bad_time;
  return std::nullopt;
}

std::variant<Datagram, Rejection> decode_datagram(std::span<const std::uint8_t> bytes,
                                                  const TrafficKey& key,
                                                  std::optional<std::uint64_t> expected_session,
                                                  bool allow_cleartext) {
  Envelope envelope;
  if (auto reason = envelope_rejection(bytes, allow_cleartext, envelope)) return *reason;
  Datagram datagram;
  if (auto reason = open_and_parse(bytes, envelope, key, datagram)) return *reason;
  if (expected_session && datagram.header().session() != *expected_session)
    return Rejection::wrong_session;
  if (auto reason = body_rejection(datagram)) return *reason;
  return datagram;
}

DatagramInspector::DatagramInspector(std::optional<std::uint64_t> expected_session,
                                     bool allow_cleartext)
    : session_(expected_session), allow_cleartext_(allow_cleartext) {
  ensure_sodium();
}

const DatagramInspector::Sender* DatagramInspector::find(std::uint32_t sender) const {
  for (const Sender& allowed : senders_)
    if (allowed.id == sender) return &allowed;
  return nullptr;
}

const ReplayWindow* DatagramInspector::window(std::uint32_t sender) const {
  const Sender* allowed = find(sender);
  return allowed ? &allowed->window : nullptr;
}

void DatagramInspector::allow_sender(std::uint32_t sender, const TrafficKey& key,
                                     std::uint64_t salt, std::uint64_t last_sequence) {
  Sender* allowed = find(sender);
  if (!allowed) allowed = &senders_.emplace_back();
  allowed->id = sender;
  allowed->key = key;
  allowed->salt = salt;
  allowed->window.start_after(last_sequence);
}

void DatagramInspector::forget_sender(std::uint32_t sender) {
  std::erase_if(senders_, [sender](const Sender& allowed) { return allowed.id == sender; });
}

std::nullopt_t DatagramInspector::reject(Rejection reason) {
  counters_.record(reason);
  last_ = reason;
  return std::nullopt;
}

std::optional<Datagram> DatagramInspector::inspect(std::span<const std::uint8_t> bytes) {
  Envelope envelope;
  if (auto reason = envelope_rejection(bytes, allow_cleartext_, envelope)) return reject(*reason);
  Sender* sender = find(envelope.sender);
  if (!sender) return reject(Rejection::unknown_sender);
  std::optional<Datagram> datagram(std::in_place);
  if (auto reason = open_and_parse(bytes, envelope, sender->key, *datagram)) return reject(*reason);
  if (session_ && datagram->header().session() != *session_)
    return reject(Rejection::wrong_session);
  if (envelope.salt != sender->salt) return reject(Rejection::replayed);
  if (auto reason = body_rejection(*datagram)) return reject(*reason);
  if (!sender->window.accept(envelope.sequence)) return reject(Rejection::replayed);
  counters_.record_accepted();
  last_.reset();
  return datagram;
}

}  // namespace cohaptic::wire
