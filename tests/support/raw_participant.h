// RawParticipant: a participant made by hand over plain sockets, speaking protocol 3 through
// the codec alone (no ServerConnection, no ClientNetwork), so that a test can make it do
// what a real client never does: stop reading its control connection while it presses,
// replay its join on another connection, claim another slot. Blocking sockets with a
// receive timeout; one thread, or its own sample thread (press_along). Positions in m.
#pragma once

#include <Eigen/Core>
#include <asio.hpp>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "cohaptic/messages.pb.h"
#include "proto/wire/frame_codec.h"
#include "proto/wire/sealer.h"
#include "proto/wire/traffic_keys.h"

namespace cohaptic::testing {

class RawParticipant {
 public:
  struct Options {
    std::uint16_t server_port = 0;
    int slot = 0;
    std::string name = "raw";
    int tcp_receive_buffer = 0;  ///< >0: SO_RCVBUF before connecting (a small window fills fast)
    bool encrypt = true;
  };
  RawParticipant(Options options, wire::ClientKeys keys);
  ~RawParticipant();
  RawParticipant(const RawParticipant&) = delete;
  RawParticipant& operator=(const RawParticipant&) = delete;

  /// Connects, takes the greeting, joins, and reads until the Welcome. Throws Error with
  /// the server's text if it refuses, or if nothing comes within `timeout`.
  wire::Welcome join(std::chrono::milliseconds timeout = std::chrono::seconds(10));
  /// Every byte the server sent on the control connection so far (greeting and frames, sealed).
  const std::vector<std::uint8_t>& received_bytes() const { return received_; }
  /// The Join as it went out (sealed), for a replay.
  const std::vector<std::uint8_t>& join_bytes() const { return join_bytes_; }
  /// Sends `bytes` on the control connection as they are.
  void send_raw(const std::vector<std::uint8_t>& bytes);

  /// One tool sample over UDP, sealed with this participant's key.
  void send_sample(const Eigen::Vector3d& position);
  /// A thread sending a sample along `path(t)` (t in s from now) every millisecond, until
  /// destroyed or stop(). It never reads the control connection.
  void press_along(std::function<Eigen::Vector3d(double)> path);
  void stop();
  std::uint64_t samples_sent() const { return samples_sent_; }
  /// How many datagrams reach this participant's UDP socket within `span` (read and dropped).
  std::size_t datagrams_within(std::chrono::milliseconds span);

 private:
  bool read_some(std::chrono::steady_clock::time_point deadline);

  Options options_;
  wire::ClientKeys keys_;
  asio::io_context io_;
  asio::ip::tcp::socket tcp_;
  asio::ip::udp::socket udp_;
  asio::ip::udp::endpoint server_udp_;
  wire::TrafficKey key_;
  wire::FrameSealer frames_;
  wire::DatagramSealer datagrams_;
  std::vector<std::uint8_t> received_, join_bytes_;
  std::thread sender_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> samples_sent_{0};
};

}  // namespace cohaptic::testing
