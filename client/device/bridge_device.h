// BridgeDevice: the client's end of the external-device bridge (BRIDGE.md). A program
// built on a vendor SDK sends pose packets to a UDP port the client listens on and
// receives force packets back; to the haptic loop it is just another HapticDevice.
//
// Packets are those of bridge_protocol.h (little-endian, fixed size). The first source
// (address and port) that sends a well-formed pose packet is the program; datagrams from any
// other source are dropped and counted, as are packets of the wrong size or magic, with a
// non-finite value, or older (by sequence, modulo 2^32) than the newest pose accepted.
// After a timeout, the next pose from the program is accepted whatever its sequence, so a
// program restarted on the same port picks up where it left off.
//
// read(t) drains the socket without blocking (at most max_packets_per_read datagrams),
// keeps the newest pose, and reports it; the state is invalid before the first pose, when
// the newest pose says "not valid" (the position then is the last valid one), and when no
// pose has been accepted for more than timeout_s of the loop's time (default 50 ms).
// write_force() sends one force packet to the program (non-blocking; a full socket buffer
// drops it, counted); before the program is known it sends nothing.
//
// Threads: start()/stop() outside the loop; read()/write_force() from the haptic thread
// only, which make their own non-blocking system calls but neither allocate nor lock.
// counters(), has_peer(), peer() and local_port() may be called from any thread.
// Units: m, N, s.
#pragma once

#include <asio.hpp>

#include <Eigen/Core>
#include <array>
#include <atomic>
#include <cstdint>
#include <optional>
#include <string>

#include "client/device/bridge_protocol.h"
#include "common/haptics/haptic_device.h"

namespace cohaptic {

struct BridgeOptions {
  std::string host = "127.0.0.1";  ///< address to listen on ("0.0.0.0" for every interface)
  std::uint16_t port = 0;          ///< 0: an ephemeral port (see local_port())
  double timeout_s = 0.05;         ///< no pose for longer than this: invalid
  int max_packets_per_read = 256;  ///< bounds the time one read() may take
};

/// A snapshot of what the bridge has seen since start().
struct BridgeCounters {
  std::uint64_t received = 0;  ///< datagrams read from the socket
  std::uint64_t accepted = 0;  ///< poses taken as the newest
  std::uint64_t bad_size = 0;
  std::uint64_t bad_magic = 0;
  std::uint64_t non_finite = 0;
  std::uint64_t foreign_source = 0;  ///< from a source other than the program
  std::uint64_t stale = 0;           ///< not newer than the newest pose accepted
  std::uint64_t receive_errors = 0;  ///< socket errors other than "would block"
  std::uint64_t forces_sent = 0;
  std::uint64_t send_failed = 0;  ///< force packets the socket refused (e.g. buffer full)
  std::uint64_t dropped() const {
    return bad_size + bad_magic + non_finite + foreign_source + stale;
  }
};

class BridgeDevice : public HapticDevice {
 public:
  /// Throws Error for a non-positive timeout or force limit. Opens nothing until start().
  BridgeDevice(BridgeOptions options, double force_limit);
  ~BridgeDevice() override;

  std::string describe() const override;
  /// Opens the socket and binds it; throws Error if the address is bad or the port taken.
  void start() override;
  DeviceState read(double time_s) override;
  void write_force(const Eigen::Vector3d& force, double time_s) override;
  double force_limit() const override { return force_limit_; }
  /// Logs the counters and closes the socket.
  void stop() override;

  /// The port bound by start() (useful with port 0); 0 before start().
  std::uint16_t local_port() const { return local_port_.load(std::memory_order_relaxed); }
  BridgeCounters counters() const;
  bool has_peer() const { return has_peer_.load(std::memory_order_acquire); }
  /// "address:port" of the program, or "" while it is unknown.
  std::string peer() const;
  /// The newest pose accepted (haptic thread, or after stop()).
  const bridge::PosePacket& newest_pose() const { return newest_; }

 private:
  struct AtomicCounters {
    std::atomic<std::uint64_t> received{0}, accepted{0}, bad_size{0}, bad_magic{0}, non_finite{0},
        foreign_source{0}, stale{0}, receive_errors{0}, forces_sent{0}, send_failed{0};
  };
  static void bump(std::atomic<std::uint64_t>& counter) {
    counter.fetch_add(1, std::memory_order_relaxed);
  }
  /// Handles one datagram of `size` bytes from sender_.
  void take(std::size_t size, double time_s, bool& timed_out);

  BridgeOptions options_;
  double force_limit_;
  asio::io_context io_;
  asio::ip::udp::socket socket_;
  std::atomic<std::uint16_t> local_port_{0};
  asio::ip::udp::endpoint sender_;  // scratch for receive_from
  asio::ip::udp::endpoint peer_;    // written once, before has_peer_ turns true
  std::atomic<bool> has_peer_{false};
  std::array<std::uint8_t, 2048> rx_{};
  bridge::ForceBytes tx_{};
  bridge::PosePacket newest_;
  bool have_pose_ = false;
  double last_accept_time_s_ = 0.0;  // loop time of the read() that accepted newest_
  Eigen::Vector3d last_valid_position_ = Eigen::Vector3d::Zero();
  bool valid_now_ = false;  // what the last read() reported, for the force packet's flags
  AtomicCounters counters_;
};

}  // namespace cohaptic
