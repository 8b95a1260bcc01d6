// The server's figures for people: the one-line status logged every --status interval
// (I/O thread) and the JSON report written at exit (--report, under "server"; docs/reports.md
// "Server report" lists its fields, and `summarize` and the tests read them).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "proto/wire/rejection.h"
#include "server/connection_handler.h"
#include "server/loop_statistics.h"
#include "server/serve_options.h"

namespace cohaptic {

/// What the report and the status line are made of.
struct ServerFigures {
  const ServeOptions& options;
  const std::string& scene_name;
  double min_sim_rate_hz;  ///< the scene's (haptic.min_sim_rate_hz)
  LoopSummary loop;
  ConnectionCounters connections;
  const wire::RejectionCounters& datagrams;
  std::uint64_t condition_switches =
      0;  ///< switches of the served condition (--condition, --control)
  /// Each switch: the server's session time [s] and the condition it served.
  std::vector<std::pair<double, std::string>> switch_log = {};
};

nlohmann::json server_report(const ServerFigures& figures);

/// "t 12 s | users 2/2 | sim 998 Hz, step p99 0.41 ms | ..."
std::string status_line(const ServerFigures& figures, int users, int slots);

}  // namespace cohaptic
