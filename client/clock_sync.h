// ClockSync: the client's estimate of the server's clock, on the I/O thread. It sends a
// clock ping every kPingInterval; each pong completes an NTP-style sample
// (common/sync/clock_offset.h: the sample with the smallest round trip wins). With the
// estimate it converts between the clocks (own tool samples are stamped with the server's
// clock, remote ones played out against the client's) and measures the one-way delay of
// every datagram from the server. Units: ns of CLOCK_MONOTONIC.
#pragma once

#include <asio.hpp>
#include <chrono>
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>

#include "cohaptic/messages.pb.h"
#include "common/sync/clock_offset.h"
#include "common/util/histogram.h"

namespace cohaptic {

/// Between clock pings: ten samples a second keep the estimate fresh at a few hundred
/// bytes a second.
inline constexpr std::chrono::milliseconds kPingInterval{100};

class ClockSync {
 public:
  /// `send_ping` sends a datagram to the server (dropping it when not connected).
  ClockSync(asio::io_context& io, std::function<void(wire::Datagram&)> send_ping);

  /// Starts the pings.
  void start();
  void stop();
  /// A new session (another server clock, perhaps): forgets the estimate and pings now.
  void restart();

  void on_pong(const wire::ClockPong& pong, std::int64_t arrival_ns);
  /// A datagram from the server, sent at `sender_time_ns` (its clock), arrived at `arrival_ns`.
  void observe(std::int64_t sender_time_ns, std::int64_t arrival_ns);

  std::int64_t to_server(std::int64_t client_ns) const { return estimate_.to_server(client_ns); }
  std::int64_t to_client(std::int64_t server_ns) const { return estimate_.to_client(server_ns); }

  /// Server-to-client delays of the datagrams observed [ns] (read on the I/O thread).
  const Histogram& one_way_delay() const { return one_way_ns_; }
  /// The report's "clock" (offset, round trip) and "one_way_delay_ms" (p50, p99, samples).
  void add_to_report(nlohmann::json& report) const;

 private:
  void ping();
  void schedule();

  asio::steady_timer timer_;
  std::function<void(wire::Datagram&)> send_ping_;
  ClockOffsetEstimator estimate_;
  Histogram one_way_ns_{10'000, 100'000};  // server -> client, 10 us bins up to 1 s
};

}  // namespace cohaptic
