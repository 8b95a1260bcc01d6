// SimulationServer: the networked simulation server, `cohaptic-server --scene ...`
// (docs/server.md). It loads the scene, builds the model and its compliance,
// and wires together the parts that each do one job:
//   - ConnectionHandler (connection_handler.h), on the I/O thread: connections, user slots,
//     tool samples in and relayed, clock pongs, the injected shift delay, each step's
//     messages out;
//   - SimulationLoop (simulation_loop.h), on the simulation thread: latest tool samples
//     in -> Simulation step -> an Outbox of IRs (P1) or forces (P0) per step, posted to
//     the I/O thread in one piece;
//   - DisplayWriter (display_writer.h), on its own thread, with --display;
//   - the recording (server_recording.h, with --record), the statistics
//     (loop_statistics.h) and the report (server_report.h).
// Tool samples cross from the I/O thread to the simulation thread through ToolInputs
// (tool_inputs.h), the one lock between them; the simulation thread never blocks on a
// client. The thread that calls run() runs the I/O context; it also handles SIGINT and
// SIGTERM, stop() and the duration, then shuts the others down and writes the report.
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

  /// Serves until stop(), a signal or the duration; then says goodbye to the clients,
  /// closes the recording and writes the report. Blocks. Throws Error, after all of that,
  /// if the session ended because kMaxConsecutiveStepFailures simulation steps failed in
  /// a row (simulation_loop.h): the message names the last error.
  void run();
  /// Asks run() to finish; callable from any thread.
  void stop();

  std::uint16_t tcp_port() const;
  std::uint16_t udp_port() const;
  /// The report (docs/reports.md "Server report"); complete once run() has returned.
  nlohmann::json report() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cohaptic
