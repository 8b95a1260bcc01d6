// Fuzz target: the external-device bridge protocol (client/device/bridge_protocol.h), the
// UDP packets a vendor-SDK program exchanges with the client.
//
// Input: one received datagram, decoded both as a pose and as a force packet. Properties:
//   - a packet of the wrong size is refused as bad_size, then one with the wrong magic as
//     bad_magic; any other is accepted or refused as non_finite;
//   - an accepted packet has a finite time and encodes back to the bytes received (the
//     force packet's reserved word aside, which is sent as zero).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>

#include "client/device/bridge_protocol.h"
#include "tests/fuzz/fuzz_support.h"

namespace {

using namespace cohaptic;
using fuzz::require;

template <class Packet, class Bytes, std::size_t kSize>
void check(std::span<const std::uint8_t> bytes, const std::array<std::uint8_t, 4>& magic,
           std::size_t compared) {
  Packet packet;
  const bridge::PacketStatus status = bridge::decode(bytes, packet);
  if (bytes.size() != kSize) {
    require(status == bridge::PacketStatus::bad_size, "a packet of the wrong size is bad_size");
    return;
  }
  if (!std::equal(magic.begin(), magic.end(), bytes.begin())) {
    require(status == bridge::PacketStatus::bad_magic,
            "a packet with the wrong magic is bad_magic");
    return;
  }
  if (status == bridge::PacketStatus::non_finite) return;
  require(status == bridge::PacketStatus::ok, "a well-formed packet decodes");
  require(std::isfinite(packet.device_time_s), "an accepted packet's time is finite");
  Bytes again{};
  bridge::encode(packet, again);
  require(std::equal(again.begin(), again.begin() + static_cast<std::ptrdiff_t>(compared),
                     bytes.begin()),
          "an accepted packet encodes back to its bytes");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> bytes(data, size);
  check<bridge::PosePacket, bridge::PoseBytes, bridge::kPosePacketSize>(bytes, bridge::kPoseMagic,
                                                                        bridge::kPosePacketSize);
  check<bridge::ForcePacket, bridge::ForceBytes, bridge::kForcePacketSize>(
      bytes, bridge::kForceMagic, bridge::kForcePacketSize - 4);
  return 0;
}
