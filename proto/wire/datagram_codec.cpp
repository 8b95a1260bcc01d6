#include "proto/wire/datagram_codec.h"

#include <algorithm>

#include "common/util/error.h"
#include "proto/wire/sodium_ready.h"
#include "proto/wire/vec3_convert.h"

namespace cohaptic::wire {
namespace {

/// Size, tag and parse: the checks before anything in the message can be trusted.
std::optional<Rejection> open_and_parse(std::span<const std::uint8_t> bytes, const SessionKey& key, Datagram& out) {
  if (bytes.size() > kMaxDatagramBytes) return Rejection::oversized;
  if (bytes.size() < kTagBytes) return Rejection::truncated;
  const std::optional<std::span<const std::uint8_t>> payload = open(bytes, key);
  if (!payload) return Rejection::bad_tag;
  if (!out.ParseFromArray(payload->data(), static_cast<int>(payload->size()))) return Rejection::truncated;
  return std::nullopt;
}

std::optional<Rejection> header_rejection(const Header& header, std::optional<std::uint64_t> expected_session) {
  if (header.protocol_version() != kProtocolVersion) return Rejection::bad_version;
  if (expected_session && header.session() != *expected_session) return Rejection::wrong_session;
  return std::nullopt;
}

}  // namespace

void encode_datagram(const Datagram& datagram, const SessionKey& key, std::vector<std::uint8_t>& out) {
  const std::size_t payload = datagram.ByteSizeLong();
  if (payload + kTagBytes > kMaxDatagramBytes)
    throw cohaptic::Error(fmt::format("datagram of {} bytes with its tag exceeds the limit of {} bytes",
                                      payload + kTagBytes, kMaxDatagramBytes));
  out.resize(payload + kTagBytes);
  datagram.SerializeWithCachedSizesToArray(out.data());  // sizes cached by ByteSizeLong()
  const std::array<std::uint8_t, kTagBytes> tag = authentication_tag(std::span(out.data(), payload), key);
  std::copy(tag.begin(), tag.end(), out.begin() + static_cast<std::ptrdiff_t>(payload));
}

std::vector<std::uint8_t> encode_datagram(const Datagram& datagram, const SessionKey& key) {
  std::vector<std::uint8_t> out;
  encode_datagram(datagram, key, out);
  return out;
}

std::optional<Rejection> body_rejection(const Datagram& datagram) {
  const auto clock = [](std::int64_t ns) { return ns >= 0 && ns < kMaxClockNs; };
  bool times_in_range = clock(datagram.header().sender_time_ns());
  switch (datagram.body_case()) {
    case Datagram::BODY_NOT_SET: return Rejection::empty;
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
    case Datagram::kPing: times_in_range = times_in_range && clock(datagram.ping().client_send_ns()); break;
    case Datagram::kPong: {
      const ClockPong& pong = datagram.pong();
      times_in_range = times_in_range && clock(pong.client_send_ns()) && clock(pong.server_receive_ns()) &&
                       clock(pong.server_send_ns());
      break;
    }
  }
  if (!times_in_range) return Rejection::bad_time;
  return std::nullopt;
}

std::variant<Datagram, Rejection> decode_datagram(std::span<const std::uint8_t> bytes, const SessionKey& key,
                                                  std::optional<std::uint64_t> expected_session) {
  Datagram datagram;
  if (auto reason = open_and_parse(bytes, key, datagram)) return *reason;
  if (auto reason = header_rejection(datagram.header(), expected_session)) return *reason;
  if (auto reason = body_rejection(datagram)) return *reason;
  return datagram;
}

DatagramInspector::DatagramInspector(const SessionKey& key, std::optional<std::uint64_t> expected_session)
    : key_(key), session_(expected_session) {
  ensure_sodium();
}

const ReplayWindow* DatagramInspector::find(std::uint32_t sender) const {
  for (const auto& [id, window] : windows_)
    if (id == sender) return &window;
  return nullptr;
}

void DatagramInspector::allow_sender(std::uint32_t sender) {
  if (ReplayWindow* window = find(sender)) window->reset();
  else windows_.emplace_back(sender, ReplayWindow{});
}

void DatagramInspector::forget_sender(std::uint32_t sender) {
  std::erase_if(windows_, [sender](const auto& entry) { return entry.first == sender; });
}

std::nullopt_t DatagramInspector::reject(Rejection reason) {
  counters_.record(reason);
  last_ = reason;
  return std::nullopt;
}

std::optional<Datagram> DatagramInspector::inspect(std::span<const std::uint8_t> bytes) {
  std::optional<Datagram> datagram(std::in_place);
  if (auto reason = open_and_parse(bytes, key_, *datagram)) return reject(*reason);
  const Header& header = datagram->header();
  if (auto reason = header_rejection(header, session_)) return reject(*reason);
  ReplayWindow* window = find(header.sender());
  if (!window) return reject(Rejection::unknown_sender);
  if (auto reason = body_rejection(*datagram)) return reject(*reason);
  if (!window->accept(header.sequence())) return reject(Rejection::replayed);
  counters_.record_accepted();
  last_.reset();
  return datagram;
}

}  // namespace cohaptic::wire
