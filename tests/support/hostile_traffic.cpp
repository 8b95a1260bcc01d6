#include "support/hostile_traffic.h"

#include <gtest/gtest.h>

#include <string>

#include "proto/wire/envelope.h"
#include "proto/wire/header.h"
#include "proto/wire/sealer.h"
#include "proto/wire/session_key.h"
#include "proto/wire/traffic_keys.h"

namespace cohaptic::testing {

std::uint64_t session_id(const ChildProcess& server) {
  const std::string log = server.log_text();
  const auto at = log.find("session ");
  EXPECT_NE(at, std::string::npos) << log;
  return std::stoull(log.substr(at + 8, 16), nullptr, 16);
}

HostileDatagrams::HostileDatagrams(std::uint64_t session, std::mt19937& rng) : rng_(rng) {
  const wire::SessionKey dev = wire::development_key();
  wire::DatagramSealer as_bob(wire::participant_key(dev, 1), session, wire::sender_of_slot(0));
  wire::DatagramSealer replayer(wire::participant_key(dev, 0), session, wire::sender_of_slot(0));
  for (int i = 0; i < 64; ++i) {
    wire::Datagram sample;
    sample.mutable_tool()->set_user(0);
    sample.mutable_tool()->mutable_position()->set_z(-0.05);
    authentic_.push_back(as_bob.seal(sample));
    authentic_.push_back(replayer.seal(sample));
  }
}

Bytes HostileDatagrams::random_bytes(std::size_t size) {
  Bytes bytes(size);
  for (auto& byte : bytes) byte = static_cast<std::uint8_t>(rng_());
  return bytes;
}

Bytes HostileDatagrams::next() {
  Bytes bytes;
  switch (rng_() % 6) {
    case 0:
      return random_bytes(rng_() % 1600);  // empty to oversized
    case 1:                                // protocol 1 or 2's first byte
      bytes = random_bytes(40 + rng_() % 200);
      bytes[0] = 0x0a;
      return bytes;
    case 2:  // an envelope naming user 0 or 1, and no valid tag
      bytes = random_bytes(60 + rng_() % 100);
      wire::write_envelope({wire::kProtocolVersion, wire::kEncryptedFlag,
                            1 + static_cast<std::uint32_t>(rng_() % 2), rng_(), rng_()},
                           bytes.data());
      return bytes;
    case 3:
      return authentic_[rng_() % authentic_.size()];  // another's key, or another sealer
    default:                                          // one of those with a bit flipped
      bytes = authentic_[rng_() % authentic_.size()];
      bytes[rng_() % bytes.size()] ^= static_cast<std::uint8_t>(1u << (rng_() % 8));
      return bytes;
  }
}

}  // namespace cohaptic::testing
