// SimulationServer: the networked simulation server (DESIGN.md §4-§6).
//
// Threads, each with one job:
//   - the I/O thread runs an asio io_context: it accepts TCP control connections (join,
//     welcome, IRs, events), receives and relays UDP tool samples, answers clock pings,
//     and applies the injected shift delay to every link, each direction;
//   - the simulation thread runs the loop: latest tool samples in -> active sets and M~
//     (Simulation) -> IRs out (P1) or forces out (P0), at up to `sim_rate_hz`;
//   - the thread that calls run() waits for SIGINT/SIGTERM, stop() or the duration,
//     then shuts the others down cleanly and writes the report.
// The simulation thread never blocks on a client: it hands messages to the I/O thread
// with asio::post; tool samples cross the other way under a small mutex.
// One user slot per tool of the scene; a vanished client's tool is released.
#pragma once

#include <atomic>
#include <memory>
#include <nlohmann/json.hpp>

#include "server/serve_options.h"

namespace cohaptic {

class SimulationServer {
 public:
  /// Loads the scene, builds the model and its compliance, binds the sockets. Throws
  /// Error (with the cause) if any of it fails.
  explicit SimulationServer(ServeOptions options);
  ~SimulationServer();
  SimulationServer(const SimulationServer&) = delete;
  SimulationServer& operator=(const SimulationServer&) = delete;

  /// Serves until stop(), a signal or the duration; then writes the report. Blocks.
  void run();
  /// Asks run() to finish; callable from any thread.
  void stop();

  std::uint16_t tcp_port() const;
  std::uint16_t udp_port() const;
  nlohmann::json report() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cohaptic
