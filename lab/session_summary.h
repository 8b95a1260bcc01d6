// The summary of a networked session: the server's and the clients' JSON reports merged
// into one, a table on stdout, and a verdict (`cohaptic-lab summarize`, used by
// `make demo`). Healthy means:
//   - the server's simulation loop ran and none of its steps failed (the report's
//     failed_steps: the problem names the count and the last error);
//   - every client joined, ran its haptic loop at >= 95 % of its rate, received IRs (P1)
//     or forces (P0), touched the object, and never output a non-finite force;
//   - no datagram or control frame was rejected (nobody else is on the demo's loopback);
//   - the haptic period's p99 is within 100 us of the period, or, on a machine whose bare
//     timer cannot do that, within 100 us of that timer floor measured at the same time;
//   - at most 0.1 % of the ticks missed their deadline, or, when the bare timer missed
//     deadlines too (the machine stalled), at most 0.1 % more than it did;
//   - with two or more users, each one's coupling (the part of its force due to the
//     others) peaks above 10 % of its own peak force.
// Every failed criterion is listed by name.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "lab/lab_command.h"

namespace cohaptic {

struct SessionVerdict {
  nlohmann::json report;              ///< {"server": ..., "clients": [...], "healthy": bool, "problems": [...]}
  std::vector<std::string> problems;  ///< empty when healthy
  std::vector<std::string> notes;     ///< worth knowing, not failures
};

SessionVerdict summarize_session(const nlohmann::json& server, const std::vector<nlohmann::json>& clients);

/// Reads the reports, prints the table, writes `out` (if not empty); exit code 0 if healthy.
int run_summarize(const std::filesystem::path& server_report, const std::vector<std::filesystem::path>& client_reports,
                  const std::filesystem::path& out);

/// `cohaptic-lab summarize --server-report FILE --client-report FILE... [--out FILE]`.
LabCommand add_summarize_command(CLI::App& lab);

}  // namespace cohaptic
