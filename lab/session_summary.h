// The summary of a networked session: the server's and the clients' JSON reports merged
// into one, a table on stdout, and a verdict (`cohaptic-lab summarize`, used by
// `make demo`) judged by what the users felt. Each criterion, its value and its threshold
// are in the report ("criteria") and the table; healthy means every one holds:
//   - server: no datagram or control frame rejected (nobody else is on the demo's
//     loopback); no simulation step failed; the step rate at least 90 % of its target (the
//     --sim-rate-hz asked for, else the scene's haptic.min_sim_rate_hz);
//   - each client: the haptic loop ran at >= 95 % of its rate (or lost no more ticks than the
//     bare timer beside it missed deadlines: the machine's stall), received IRs (P1) or forces
//     (P0), touched the object, never output a non-finite force, rejected no datagram;
//     its force never faded while pushing; at most 0.1 % of its ticks at the force limit;
//     the age of its IR (P1) or force (P0): p99 within 4 steps at the target rate plus the
//     injected delay (50 ms at least, the fade age at most), max below the fade age;
//   - the haptic period's p99 within 100 us of the period, or, on a machine whose bare
//     timer cannot do that, within 100 us (or a tenth, if more) of that timer floor
//     measured at the same time;
//     at most 0.1 % of the ticks (or a twentieth of the bare timer's misses, or three times
//     their square root, if more) missed their deadline beyond what the bare timer missed.
// A failed criterion is a problem naming its cause. Notes are worth knowing and judge
// nothing: how much the users felt of each other (the experiment's design), a machine
// whose bare timer was as late as the loop or missed as many deadlines (its host's steal time
// named, in a virtual machine).
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "lab/lab_command.h"

namespace cohaptic {

/// One thing judged: who (server or a user), what, its value and threshold as shown.
struct HealthCriterion {
  std::string who, what, value, threshold;
  bool ok = true;
};

struct SessionVerdict {
  nlohmann::json report;  ///< {"server", "clients", "healthy", "problems", "notes", "criteria"}
  std::vector<HealthCriterion> criteria;
  std::vector<std::string> problems;  ///< empty when healthy
  std::vector<std::string> notes;     ///< worth knowing, not failures
};

SessionVerdict summarize_session(const nlohmann::json& server,
                                 const std::vector<nlohmann::json>& clients);

/// Whether a client's report shows missed deadlines of its own haptic loop: more than 0.1 % of
/// its ticks (or a twentieth of the floor's misses, or three times their square root, if more)
/// beyond those the bare timer floor beside it missed (a stall of the whole machine, the host's
/// steal time in a virtual machine, makes the floor miss about the same deadlines).
bool misses_deadlines_of_its_own(const nlohmann::json& client_report);

/// Reads the reports, prints the table, writes `out` (if not empty); exit code 0 if healthy.
int run_summarize(const std::filesystem::path& server_report,
                  const std::vector<std::filesystem::path>& client_reports,
                  const std::filesystem::path& out);

/// `cohaptic-lab summarize --server-report FILE --client-report FILE... [--out FILE]`.
LabCommand add_summarize_command(CLI::App& lab);

}  // namespace cohaptic
