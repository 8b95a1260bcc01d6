#include "server/server_report.h"

#include <fmt/format.h>

#include <map>
#include <string>

namespace cohaptic {

nlohmann::json server_report(const ServerFigures& figures) {
  const LoopSummary& loop = figures.loop;
  const ConnectionCounters& connections = figures.connections;
  const ServeOptions& options = figures.options;
  nlohmann::json server;
  server["scene"] = figures.scene_name;
  server["protocol"] = options.protocol == ServeProtocol::p1 ? "P1" : "P0";  // at the start
  if (!options.conditions.empty()) {
    std::vector<std::string> names;
    for (const ServedCondition& condition : options.conditions) names.push_back(condition.name);
    server["conditions"] = names;
    server["condition_switches"] = figures.condition_switches;
    nlohmann::json log = nlohmann::json::array();
    for (const auto& [time_s, served] : figures.switch_log)
      log.push_back({{"time_s", time_s}, {"served", served}});
    server["switch_log"] = log;
  }
  server["sim_rate_hz"] = loop.rate_hz();
  // What the verdict holds the rate to, whatever step delay was injected: the users feel it.
  server["target_sim_rate_hz"] = figures.min_sim_rate_hz;
  server["ir_max_age_ms"] = options.ir_max_age_s * 1e3;
  server["steps"] = loop.steps;
  server["step_ms"] = {
      {"p50", loop.step_p50_ms}, {"p99", loop.step_p99_ms}, {"max", loop.step_max_ms}};
  server["ir_build_ms"] = {
      {"p50", loop.ir_build_p50_ms}, {"p99", loop.ir_build_p99_ms}, {"count", loop.ir_builds}};
  server["ir_encode_ms"] = {{"p50", loop.ir_encode_p50_ms}, {"p99", loop.ir_encode_p99_ms}};
  server["irs_sent"] = loop.irs_sent;
  server["irs_superseded"] = loop.irs_superseded;
  server["ir_bytes_sent"] = loop.ir_bytes_sent;
  server["ir_bytes_built"] = loop.ir_bytes;
  server["boundary_nodes"] = {{"max", loop.max_boundary_nodes},
                              {"obstacle_max", loop.max_obstacle_nodes}};
  server["sphere_nodes_outside_patches"] = loop.sphere_nodes_outside_patches;
  server["forces_sent"] = loop.forces_sent;
  server["max_surface_displacement_mm"] = loop.max_surface_displacement_m * 1e3;
  if (loop.separates)
    server["separated_area_mm2"] = {{"fractured", loop.fractured_m2 * 1e6},
                                    {"vaporised", loop.vaporised_m2 * 1e6},
                                    {"groove_record_full", loop.groove_record_full}};
  server["failed_steps"] = {{"count", loop.failed_steps},
                            {"max_in_a_row", loop.max_consecutive_failures},
                            {"last_error", loop.last_failure}};
  server["datagrams"] = {{"received", figures.datagrams.accepted() + figures.datagrams.rejected()},
                         {"accepted", figures.datagrams.accepted()},
                         {"rejected", figures.datagrams.rejected()},
                         {"rejected_by_reason", figures.datagrams.snapshot()},
                         {"over_budget", connections.datagrams_over_budget},
                         {"dropped_by_kernel", connections.datagrams_dropped_by_kernel},
                         {"sent", connections.datagrams_sent},
                         {"relayed", connections.datagrams_relayed}};
  std::map<std::string, std::uint64_t> frame_rejections;
  for (wire::Rejection reason : wire::kAllRejections)
    frame_rejections.emplace(
        std::string(wire::to_string(reason)),
        connections.frames_rejected_by_reason[static_cast<std::size_t>(reason)]);
  server["control_frames"] = {{"sent", connections.frames_sent},
                              {"rejected", connections.frames_rejected},
                              {"rejected_by_reason", frame_rejections},
                              {"dropped", connections.frames_dropped}};
  server["connections"] = {{"accepted", connections.connections},
                           {"joins", connections.joins},
                           {"joins_refused", connections.joins_refused},
                           {"unjoined_evicted", connections.unjoined_evicted},
                           {"join_timeouts", connections.join_timeouts},
                           {"accept_errors", connections.accept_errors},
                           {"write_stalls", connections.write_stalls},
                           {"queue_overflows", connections.queue_overflows}};
  server["encrypted"] = options.encrypt;
  server["injected"] = {{"shift_delay_ms", options.shift.delay_ms},
                        {"jitter_ms", options.shift.jitter_ms},
                        {"loss", options.shift.loss},
                        {"reorder", options.shift.reorder},
                        {"seed", options.shift.seed},
                        {"step_nodes", options.step_nodes},
                        {"sim_rate_hz", options.sim_rate_hz},
                        {"condensation", options.naive_condensation ? "naive" : "incremental"},
                        {"datagrams_dropped_to_clients", connections.dropped_to_clients},
                        {"datagrams_dropped_from_clients", connections.dropped_from_clients}};
  server["elapsed_s"] = loop.elapsed_s;
  return server;
}

std::string status_line(const ServerFigures& figures, int users, int slots) {
  const LoopSummary& loop = figures.loop;
  std::string line = fmt::format(
      "t {:.0f} s | users {}/{} | sim {:.0f} Hz, step p99 {:.2f} ms | |B| max {} | IRs {} | "
      "datagrams in {} (rejected {}), "
      "out {}",
      loop.elapsed_s, users, slots, loop.rate_hz(), loop.step_p99_ms, loop.max_boundary_nodes,
      loop.rebuilds, figures.datagrams.accepted(), figures.datagrams.rejected(),
      figures.connections.datagrams_sent);
  if (loop.separates)
    line += fmt::format(" | separated {:.1f} mm² (fractured {:.1f}, vaporised {:.1f})",
                        (loop.fractured_m2 + loop.vaporised_m2) * 1e6, loop.fractured_m2 * 1e6,
                        loop.vaporised_m2 * 1e6);
  if (loop.failed_steps > 0) line += fmt::format(" | failed steps {}", loop.failed_steps);
  return line;
}

}  // namespace cohaptic
