// BridgePeer: the program's end of the external-device bridge (BRIDGE.md), i.e. what a
// vendor-SDK program does, as a small class: send pose packets to the client, collect the
// force packets it sends back. Used by cohaptic-bridge-example and by the tests; a real
// bridge may copy it (it only needs a UDP socket and bridge_protocol.h).
//
// The socket is bound to an ephemeral port (the client learns it from the first pose) and
// is non-blocking: send_pose() never waits, poll_forces() drains what has arrived. Force
// packets from any source but the client, malformed ones and ones older than the newest
// (by sequence) are counted and dropped. Units: m, N, s. Not thread-safe; one thread.
#pragma once

#include <asio.hpp>

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>

#include "client/device/bridge_protocol.h"

namespace cohaptic {

class BridgePeer {
 public:
  /// Resolves `client_host` (a name or an address) and opens the socket; throws Error.
  BridgePeer(const std::string& client_host, std::uint16_t client_port);

  /// Sends a pose with the next sequence number (starting at 0). False if the socket refused it.
  bool send_pose(const Eigen::Vector3d& position, double device_time_s, std::uint32_t buttons = 0,
                 bool valid = true);
  /// Sends a pose packet as given (its own sequence), e.g. to test reordering.
  bool send_pose(const bridge::PosePacket& packet);
  /// Sends arbitrary bytes, e.g. to test how the client rejects them.
  bool send_bytes(std::span<const std::uint8_t> bytes);

  /// Drains the force packets that have arrived without blocking; returns how many were accepted.
  std::size_t poll_forces();
  /// The newest force packet accepted so far, if any.
  const std::optional<bridge::ForcePacket>& newest_force() const { return newest_force_; }

  std::uint32_t next_sequence() const { return sequence_; }
  std::uint16_t local_port() const;
  std::uint64_t forces_received() const { return forces_received_; }
  std::uint64_t forces_dropped() const { return forces_dropped_; }
  std::uint64_t send_failed() const { return send_failed_; }
  std::string client() const;

 private:
  asio::io_context io_;
  asio::ip::udp::socket socket_;
  asio::ip::udp::endpoint client_;
  asio::ip::udp::endpoint sender_;
  std::array<std::uint8_t, 2048> rx_{};
  std::uint32_t sequence_ = 0;
  std::optional<bridge::ForcePacket> newest_force_;
  std::uint64_t forces_received_ = 0;
  std::uint64_t forces_dropped_ = 0;
  std::uint64_t send_failed_ = 0;
};

}  // namespace cohaptic
