// Fuzz target: UDP datagram decoding and authentication (proto/wire/datagram_codec.h), and
// what the client does with the numbers of an accepted datagram.
//
// Input: pieces (fuzz_support.h), one datagram each. Kind bit 0 set: the bytes are a
// payload this target seals as its header's sender (fuzz_support.h), so the parser and the
// checks behind the tag are reached; bit 1 set as well: sealed in clear (cleartext, as
// --no-encryption sends it); bit 2: sealed with another participant's key (bad_tag).
// Bit 0 clear: the bytes arrive as they are (size, envelope and tag checks).
// Each datagram goes to decode_datagram() (with the key of the sender its envelope names)
// and to a DatagramInspector that holds the keys of the server and four user slots, as a
// receiving socket's would. Properties:
//   - nothing throws (a throw escapes as a crash);
//   - the inspector accepts exactly what decode_datagram() accepts, as the same message,
//     and counts every datagram once; it rejects for another reason than decode_datagram()
//     only for the sender (checked before the tag: a sender it holds no key for) or the
//     sealer (replayed: another salt than the sender's); the same bytes again are rejected
//     as replayed;
//   - decode_datagram() with another expected session rejects an accepted datagram;
//   - an accepted datagram has the protocol version, a body and only finite values;
//   - fed to the clock estimate, the clock conversions and the remote tool buffers as the
//     client feeds them, its times and positions cause no undefined behaviour (UBSan) and
//     the buffers return finite positions.
#include <cmath>
#include <cstdint>
#include <optional>
#include <span>
#include <variant>

#include "common/sync/clock_offset.h"
#include "common/sync/remote_tool_buffer.h"
#include "proto/wire/datagram_codec.h"
#include "proto/wire/envelope.h"
#include "proto/wire/header.h"
#include "proto/wire/vec3_convert.h"
#include "tests/fuzz/fuzz_support.h"

namespace {

using namespace cohaptic;
using fuzz::require;

constexpr std::int64_t kLocalStartNs =
    1'000'000'000'000;                              // the client's clock, about 17 min after boot
constexpr std::int64_t kArrivalStepNs = 1'000'000;  // one datagram per millisecond

// The client's receiving side: the clock estimate and a playout buffer per remote user.
struct Client {
  ClockOffsetEstimator clock;
  RemoteToolBuffer newest{PlayoutPolicy::newest, 0};
  RemoteToolBuffer fixed{PlayoutPolicy::fixed, 5'000'000};
  RemoteToolBuffer adaptive{PlayoutPolicy::adaptive, 5'000'000};

  void take(const wire::Datagram& datagram, std::int64_t arrival_ns) {
    if (datagram.has_pong()) {
      const wire::ClockPong& pong = datagram.pong();
      clock.add(pong.client_send_ns(), pong.server_receive_ns(), pong.server_send_ns(), arrival_ns);
    } else if (datagram.has_tool()) {
      const wire::ToolSample& sample = datagram.tool();
      const std::int64_t local_time = clock.to_client(sample.sample_time_ns());
      for (RemoteToolBuffer* buffer : {&newest, &fixed, &adaptive}) {
        buffer->add(local_time, arrival_ns, wire::from_wire(sample.position()), sample.valid());
        const PlayoutQuery query = buffer->at(arrival_ns);
        require(!query.valid || query.position.allFinite(),
                "a valid remote tool position is finite");
      }
    }
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  wire::DatagramInspector inspector;
  const auto allowed = [](std::uint32_t sender) { return sender <= wire::sender_of_slot(3); };
  for (std::uint32_t sender = wire::kServerSender; allowed(sender); ++sender)
    inspector.allow_sender(sender, fuzz::fuzz_key(sender), fuzz::kFuzzSalt);
  Client client;
  std::int64_t arrival = kLocalStartNs;
  std::uint64_t inspected = 0;

  for (const fuzz::Piece& piece : fuzz::split_pieces({data, size})) {
    arrival += kArrivalStepNs;
    const fuzz::SealOptions seal{.encrypt = (piece.kind & 2) == 0,
                                 .wrong_key = (piece.kind & 4) != 0};
    const std::vector<std::uint8_t> bytes =
        piece.kind & 1 ? fuzz::sealed_datagram(piece.bytes, seal)
                       : std::vector<std::uint8_t>(piece.bytes.begin(), piece.bytes.end());
    const std::optional<wire::Envelope> envelope = wire::read_envelope(bytes);
    const wire::TrafficKey& key = fuzz::fuzz_key(envelope ? envelope->sender : wire::kServerSender);
    const auto decoded = wire::decode_datagram(bytes, key);
    const std::optional<wire::Datagram> accepted = inspector.inspect(bytes);
    ++inspected;
    require(accepted.has_value() != inspector.last_rejection().has_value(),
            "inspect() either accepts or names a reason");
    if (!accepted) {
      const wire::Rejection reason = *inspector.last_rejection();
      if (reason == wire::Rejection::unknown_sender) {
        require(envelope && !allowed(envelope->sender),
                "unknown_sender names a sender without a key");
      } else if (reason == wire::Rejection::replayed) {
        // Another sealer's salt (checked after the session, before the body) or the window.
        const auto* decode_reason = std::get_if<wire::Rejection>(&decoded);
        require(!decode_reason || *decode_reason == wire::Rejection::empty ||
                    *decode_reason == wire::Rejection::non_finite ||
                    *decode_reason == wire::Rejection::bad_time,
                "a replay decodes, or fails only on its body");
      } else {
        require(std::holds_alternative<wire::Rejection>(decoded) &&
                    std::get<wire::Rejection>(decoded) == reason,
                "the inspector names decode_datagram()'s reason");
      }
      continue;
    }
    require(std::holds_alternative<wire::Datagram>(decoded), "what the inspector accepts decodes");
    const wire::Datagram& datagram = *accepted;
    require(std::get<wire::Datagram>(decoded).SerializeAsString() == datagram.SerializeAsString(),
            "the inspector and decode_datagram() read the same message");
    require(datagram.header().protocol_version() == wire::kProtocolVersion,
            "an accepted datagram has our version");
    require(datagram.body_case() != wire::Datagram::BODY_NOT_SET,
            "an accepted datagram has a body");
    require(!wire::body_rejection(datagram).has_value(),
            "an accepted datagram's values are finite");
    if (datagram.has_tool())
      require(wire::from_wire(datagram.tool().position()).allFinite(), "a tool position is finite");
    if (datagram.has_force())
      require(wire::from_wire(datagram.force().force()).allFinite(), "a force is finite");

    const auto other_session = wire::decode_datagram(bytes, key, datagram.header().session() + 1);
    require(std::holds_alternative<wire::Rejection>(other_session) &&
                std::get<wire::Rejection>(other_session) == wire::Rejection::wrong_session,
            "another session's datagram is rejected as wrong_session");
    require(!inspector.inspect(bytes) && inspector.last_rejection() == wire::Rejection::replayed,
            "the same datagram twice is a replay");
    ++inspected;
    client.take(datagram, arrival);
  }
  require(inspector.counters().accepted() + inspector.counters().rejected() == inspected,
          "every datagram is counted once");
  return 0;
}
