// ClientNetwork: the haptic client's I/O thread (docs/client.md "Threads"). It runs
// an asio io_context on one thread and wires together the parts that each do one job:
//   - ServerConnection (server_connection.h): the TCP control channel to the server (join,
//     welcome, IRs, events, goodbye), reconnecting every 500 ms while the server is away;
//     meanwhile no IR or force arrives, so the haptic loop fades the force to zero;
//   - IrIntake (ir_intake.h): each IR converted, checked and prepared here, then handed
//     to the haptic thread through a TripleBuffer;
//   - ClockSync (clock_sync.h): clock pings every 100 ms, the server's clock estimated
//     NTP-style (smallest round trip wins), the one-way delay measured;
//   - the UDP endpoint (net/datagram_endpoint.h): own tool samples out (drained from the
//     haptic thread's ring every millisecond and stamped with the server's clock), remote
//     tool samples, IR keep-alives and P0 forces in (validated, then handed over);
//   - optionally the recording (record_session, client_recording.h);
//   - the status reports (client_status.h): the haptic figures so far, every 200 ms and
//     once more before the goodbye, for the server's live view.
// All authentication and validation is done here: nothing unchecked reaches the haptic
// thread. Units: ns of CLOCK_MONOTONIC, m, N.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "client/haptic_loop.h"
#include "client/timer_floors.h"
#include "client/welcome.h"

namespace cohaptic {

struct ClientOptions {
  std::string host = "127.0.0.1";
  std::uint16_t port = 7400;
  std::string user_name;
  std::optional<std::filesystem::path>
      key_file;               ///< session or participant key; empty: the public development key
  bool encrypt = true;        ///< false: send in clear (authenticated), and accept the server's so
  int requested_slot = -1;    ///< -1: any free slot (a participant key: its own)
  double haptic_rate_hz = 0;  ///< the loop's rate, told the server; 0: the scene's
};

class ClientNetwork {
 public:
  /// Throws Error if the key file cannot be used (see wire/session_key.h), or names
  /// another slot than --slot.
  ClientNetwork(ClientOptions options, HapticChannels& channels);
  ~ClientNetwork();
  ClientNetwork(const ClientNetwork&) = delete;
  ClientNetwork& operator=(const ClientNetwork&) = delete;

  /// Starts the I/O thread and joins the session; returns the welcome, or throws Error
  /// if none arrives within `timeout_s`.
  WelcomeInfo start(double timeout_s);
  /// Records the session from now on (MCAP, see proto/record/session_recorder.h): the
  /// configuration, every datagram and IR received, every haptic tick, every event.
  /// Throws Error if the file cannot be created.
  void record_session(const std::filesystem::path& file, const std::string& device,
                      double force_limit);
  /// Reports the haptic loop's figures to the server from now on (status reports):
  /// `metrics` are the loop's, `floors` its timer floors; both must outlive stop(). The
  /// progress comes through the channels' `progress` buffer.
  void report_status(const HapticMetrics& metrics, const TimerFloors& floors);
  /// Stops the I/O thread (after a last drain of the haptic thread's rings, the UDP
  /// socket closed and a final status sent: call it after the haptic loop has ended, and
  /// that status carries the report's figures).
  void stop();
  /// Set by SIGINT/SIGTERM, or when the server says goodbye and never comes back.
  const std::atomic<bool>& stop_requested() const { return stop_requested_; }

  nlohmann::json report() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::atomic<bool> stop_requested_{false};
};

}  // namespace cohaptic
