// Hostile traffic for the end-to-end robustness tests and the soak: datagrams of every kind
// a hostile or broken peer may send a cohaptic-server (garbage of every size, an older
// protocol, forged envelopes, another slot's key, replays, bit flips), and the session id
// a test needs to forge them well, from the server's log.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include "common/util/child_process.h"

namespace cohaptic::testing {

using Bytes = std::vector<std::uint8_t>;

/// The session id, from the server's log line "session 0123456789abcdef".
std::uint64_t session_id(const ChildProcess& server);

/// Every kind of hostile datagram, from one source: garbage from empty to oversized,
/// protocol 1 or 2 (a protobuf first), a forged envelope naming user 0 or 1 with no valid
/// tag, an authentic datagram sealed with slot 1's development key in slot 0's name or by
/// another sealer of slot 0 (a replay: its sequences 1 to 64 are long past), bit flips of
/// those. None of them may reach the physics.
class HostileDatagrams {
 public:
  HostileDatagrams(std::uint64_t session, std::mt19937& rng);
  Bytes next();

 private:
  Bytes random_bytes(std::size_t size);

  std::mt19937& rng_;
  std::vector<Bytes> authentic_;
};

}  // namespace cohaptic::testing
