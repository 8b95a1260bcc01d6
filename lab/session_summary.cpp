#include "lab/session_summary.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <memory>

#include "common/util/atomic_file.h"
#include "common/util/error.h"

namespace cohaptic {
namespace {

nlohmann::json read_json(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw Error(fmt::format("{}: cannot read the report", file.string()));
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw Error(fmt::format("{}: not a JSON report: {}", file.string(), e.what()));
  }
}

double number(const nlohmann::json& j, const std::vector<std::string>& path) {
  const nlohmann::json* node = &j;
  for (const std::string& key : path) {
    if (!node->contains(key)) return 0;
    node = &(*node)[key];
  }
  return node->is_number() ? node->get<double>() : 0;
}

}  // namespace

bool misses_deadlines_of_its_own(const nlohmann::json& client_report) {
  const double ticks = number(client_report, {"ticks"});
  const double missed = number(client_report, {"missed_deadlines"});
  const double floor_missed = number(client_report, {"timer_floor", "missed_deadlines"});
  // Two threads stalled by the same host miss about as many deadlines, not exactly as many:
  // their counts differ by a few times the square root of the floor's (counting noise, which
  // rules a short session), by a twentieth of it (a long one), or by 0.1 % of the ticks,
  // whichever is most.
  const double margin = std::max({0.001 * ticks, 0.05 * floor_missed, 3 * std::sqrt(floor_missed)});
  return missed > 0.001 * ticks && missed - floor_missed > margin;
}

SessionVerdict summarize_session(const nlohmann::json& server,
                                 const std::vector<nlohmann::json>& clients) {
  SessionVerdict verdict;
  verdict.report["server"] = server.contains("server") ? server["server"] : server;
  verdict.report["clients"] = clients;
  const auto problem = [&](std::string text) { verdict.problems.push_back(std::move(text)); };
  // One criterion: who, what, its value and its threshold as shown; a failed one is a problem
  // in `failure`'s words (the cause, with its figures).
  const auto judge = [&](const std::string& who, const std::string& what, std::string value,
                         std::string threshold, bool ok, const std::string& failure) {
    verdict.criteria.push_back({who, what, std::move(value), std::move(threshold), ok});
    if (!ok) problem(who + ": " + failure);
  };
  const nlohmann::json& s = verdict.report["server"];
  if (number(s, {"steps"}) <= 0) problem("server: the simulation loop never ran");
  const double rejected = number(s, {"datagrams", "rejected"});
  judge("server", "datagrams rejected", fmt::format("{:.0f}", rejected), "0", rejected == 0,
        fmt::format("{:.0f} datagrams rejected", rejected));
  const double frames = number(s, {"control_frames", "rejected"});
  judge("server", "control frames rejected", fmt::format("{:.0f}", frames), "0", frames == 0,
        "control frames rejected");
  const double failed = number(s, {"failed_steps", "count"});
  judge("server", "failed simulation steps", fmt::format("{:.0f}", failed), "0", failed == 0,
        fmt::format("{:.0f} simulation steps failed ({:.0f} in a row at most), the last with: {}",
                    failed, number(s, {"failed_steps", "max_in_a_row"}),
                    s.contains("failed_steps") ? s["failed_steps"].value("last_error", "?") : "?"));
  // The server's step rate against what the scene needs (or the capped rate asked for).
  const double target_hz = number(s, {"target_sim_rate_hz"});
  const double cap_hz = number(s, {"injected", "sim_rate_hz"});
  if (target_hz > 0) {
    const double rate = number(s, {"sim_rate_hz"});
    judge("server", "simulation step rate", fmt::format("{:.1f} Hz", rate),
          fmt::format(">= {:.1f} Hz", 0.9 * target_hz), rate >= 0.9 * target_hz,
          fmt::format("the simulation stepped at {:.1f} Hz, below 90 % of its target {:g} Hz: {} "
                      "(step p99 {:.1f} ms, "
                      "max {:.0f} ms)",
                      rate, target_hz,
                      cap_hz > 0 && cap_hz < 0.9 * target_hz
                          ? fmt::format("capped by --sim-rate-hz {:g}", cap_hz)
                          : std::string("the server is starved"),
                      number(s, {"step_ms", "p99"}), number(s, {"step_ms", "max"})));
  }
  // An IR (P1) or force (P0) is due every step, plus the links' injected delay both ways.
  const double injected_ms =
      2 * (number(s, {"injected", "shift_delay_ms"}) + number(s, {"injected", "jitter_ms"}));
  if (clients.empty()) problem("no client report");

  for (const nlohmann::json& c : clients) {
    const std::string user = c.value("user", "?");
    const double ticks = number(c, {"ticks"});
    const double rate = number(c, {"haptic_rate_hz"});
    const double rate_setting = std::max(1.0, number(c, {"rate_setting_hz"}));
    const double nominal = 1e6 / rate_setting;  // the period asked for [us]
    const bool p1 = c.value("protocol", "P1") == "P1";
    if (ticks <= 0) {
      problem(user + ": the haptic loop never ran");
      continue;
    }
    // A tick late past the next deadline is a tick lost: the ticks the bare timer floor beside
    // the loop lost too are the machine's (a note below), the rest the loop's own.
    const double due_ticks = rate > 0 ? ticks * rate_setting / rate : ticks;
    const double floor_missed = number(c, {"timer_floor", "missed_deadlines"});
    const bool rate_kept = rate >= 0.95 * rate_setting;
    judge(user, "haptic rate", fmt::format("{:.1f} Hz", rate),
          fmt::format(">= {:.0f} Hz, the floor's lost ticks aside", 0.95 * rate_setting),
          rate_kept || ticks + floor_missed >= 0.95 * due_ticks,
          fmt::format("haptic rate {:.1f} Hz, below 95 % of {:g} Hz", rate, rate_setting));
    if (p1 ? number(c, {"ir", "received"}) < 1 : number(c, {"forces_received"}) < 1)
      problem(user + ": nothing to compute forces from (no IR or force received)");
    if (number(c, {"force_n", "peak"}) <= 0) problem(user + ": never touched the object");
    const double non_finite = number(c, {"non_finite_ticks"});
    judge(user, "non-finite forces", fmt::format("{:.0f}", non_finite), "0", non_finite == 0,
          "non-finite forces (zeroed)");
    const double user_rejected = number(c, {"datagrams", "rejected"});
    judge(user, "datagrams rejected", fmt::format("{:.0f}", user_rejected), "0", user_rejected == 0,
          fmt::format("{:.0f} datagrams rejected", user_rejected));
    // What the hand felt: fades (stale data while pushing) and the force limit.
    const double fades = number(c, {"fades", "count"});
    judge(
        user, "force fades while pushing",
        fmt::format("{:.0f} ({:.0f} ms, longest {:.0f} ms)", fades,
                    1e3 * number(c, {"fades", "total_s"}), 1e3 * number(c, {"fades", "longest_s"})),
        "0", fades == 0,
        fmt::format("the force faded {:.0f} time(s) while pushing ({:.0f} ms in all, the longest "
                    "{:.0f} ms): its {} "
                    "came too late",
                    fades, 1e3 * number(c, {"fades", "total_s"}),
                    1e3 * number(c, {"fades", "longest_s"}), p1 ? "IR" : "force"));
    const double clamped = number(c, {"force_n", "clamped_ticks"});
    judge(user, "ticks at the force limit",
          fmt::format("{:.0f} ({:.2f} %)", clamped, 100 * clamped / ticks), "<= 0.1 %",
          clamped <= 0.001 * ticks,
          fmt::format("{:.0f} ticks ({:.2f} %) held at the force limit: the user felt the device's "
                      "limit, not the body",
                      clamped, 100 * clamped / ticks));
    // The age of what the force is computed from: due every step (at the target rate) plus
    // the injected delay, and never as old as the age at which it fades.
    const double fade_after_ms = number(c, {"ir_age_ms", "fade_after"});
    if (target_hz > 0 && fade_after_ms > 0) {
      const char* what = p1 ? "IR age" : "force age";
      const double bound_ms =
          std::min(fade_after_ms, std::max(50.0, 4e3 / target_hz + injected_ms));
      const double p99 = number(c, {"ir_age_ms", "p99"}), max = number(c, {"ir_age_ms", "max"});
      judge(user, std::string(what) + " p99", fmt::format("{:.1f} ms", p99),
            fmt::format("<= {:.0f} ms", bound_ms), p99 <= bound_ms,
            fmt::format("{} p99 {:.1f} ms, above {:.0f} ms (4 steps at {:g} Hz plus the injected "
                        "delay, at most the "
                        "fade age)",
                        what, p99, bound_ms, target_hz));
      judge(user, std::string(what) + " max", fmt::format("{:.1f} ms", max),
            fmt::format("< {:.0f} ms", fade_after_ms), max < fade_after_ms,
            fmt::format("{} reached {:.0f} ms, the age at which the force fades", what, max));
    }
    const double p99 = number(c, {"period_us", "p99"});
    const double floor_p99 = number(c, {"timer_floor", "period_us", "p99"});
    // Beside a floor late by milliseconds (a host that stalls its vCPUs), two p99s of that
    // tail, each from a few thousand periods, differ by a tenth with no fault of the loop's.
    const double floor_margin = std::max(100.0, 0.1 * floor_p99);
    const bool as_late_as_the_floor = p99 <= floor_p99 + floor_margin;
    judge(user, "haptic period p99", fmt::format("{:.0f} us (floor {:.0f} us)", p99, floor_p99),
          fmt::format("<= {:.0f} us or floor + {:.0f} us", nominal + 100, floor_margin),
          p99 <= nominal + 100 || as_late_as_the_floor,
          fmt::format("haptic period p99 {:.0f} us, more than 100 us above {:.0f} us and more "
                      "than {:.0f} us above the timer floor ({:.0f} us)",
                      p99, nominal, floor_margin, floor_p99));
    if (p99 > nominal + 100 && as_late_as_the_floor)
      verdict.notes.push_back(fmt::format(
          "{}: period p99 {:.0f} us exceeds {:.0f} + 100 us, but so does this machine's "
          "bare timer (p99 {:.0f} us)",
          user, p99, nominal, floor_p99));
    // A stall of the whole machine makes the bare timer miss the same deadlines: only the
    // misses beyond the floor's are the loop's own.
    const double missed = number(c, {"missed_deadlines"});
    // The timer floor is the worst of one per CPU; each also says how long the host held its
    // CPU back (steal time, in a virtual machine), which names a stall the host made.
    std::string steal;
    if (c.contains("timer_floor") && c["timer_floor"].contains("cpus"))
      for (const nlohmann::json& cpu : c["timer_floor"]["cpus"])
        if (cpu.contains("host_steal_ms"))
          steal += fmt::format("{}CPU {} {:.0f} ms", steal.empty() ? "; host steal time: " : ", ",
                               cpu.value("cpu", -1), number(cpu, {"host_steal_ms"}));
    const bool own_misses = misses_deadlines_of_its_own(c);
    judge(user, "missed deadlines", fmt::format("{:.0f} (floor {:.0f})", missed, floor_missed),
          "<= 0.1 % beyond the floor's", !own_misses,
          fmt::format("{:.0f} missed deadlines ({:.2f} %), the bare timer floor {:.0f}{}", missed,
                      100 * missed / ticks, floor_missed, steal));
    if (!own_misses && missed > 0)
      verdict.notes.push_back(fmt::format(
          "{}: {:.0f} missed deadlines{} (timer floor missed {:.0f}{})", user, missed,
          rate_kept ? std::string()
                    : fmt::format(", so a haptic rate of {:.1f} Hz, the machine's", rate),
          floor_missed, steal));
    // How much users feel of each other is the experiment's design (two tools far apart
    // feel little), not the session's health: a note. A dynamic body's client does not
    // measure it (reports before that flag always did).
    const bool coupling_measured =
        !c.contains("coupling_n") || c["coupling_n"].value("measured", true);
    if (clients.size() > 1 && coupling_measured &&
        number(c, {"coupling_n", "peak"}) <= 0.1 * number(c, {"force_n", "peak"}))
      verdict.notes.push_back(
          fmt::format("{}: coupling peak {:.3f} N, at most 10 % of its peak force {:.3f} N: the "
                      "users felt little of each other",
                      user, number(c, {"coupling_n", "peak"}), number(c, {"force_n", "peak"})));
  }
  verdict.report["healthy"] = verdict.problems.empty();
  verdict.report["problems"] = verdict.problems;
  verdict.report["notes"] = verdict.notes;
  nlohmann::json& criteria = verdict.report["criteria"] = nlohmann::json::array();
  for (const HealthCriterion& c : verdict.criteria)
    criteria.push_back({{"who", c.who},
                        {"criterion", c.what},
                        {"value", c.value},
                        {"threshold", c.threshold},
                        {"ok", c.ok}});
  return verdict;
}

int run_summarize(const std::filesystem::path& server_report,
                  const std::vector<std::filesystem::path>& client_reports,
                  const std::filesystem::path& out) {
  std::vector<nlohmann::json> clients;
  for (const auto& file : client_reports) clients.push_back(read_json(file));
  const SessionVerdict verdict = summarize_session(read_json(server_report), clients);
  const nlohmann::json& s = verdict.report["server"];
  fmt::print(
      "server   {} {}, sim {:.0f} Hz, IR build p50 {:.2f} ms p99 {:.2f} ms, |B| max {:.0f}, IRs "
      "{:.0f} ({:.0f} kB)\n",
      s.value("scene", "?"), s.value("protocol", "?"), number(s, {"sim_rate_hz"}),
      number(s, {"ir_build_ms", "p50"}), number(s, {"ir_build_ms", "p99"}),
      number(s, {"boundary_nodes", "max"}), number(s, {"ir_build_ms", "count"}),
      number(s, {"ir_bytes_sent"}) / 1000);
  fmt::print("\n{:<10} {:>8} {:>22} {:>8} {:>18} {:>12} {:>12} {:>10} {:>12}\n", "user", "rate Hz",
             "period us p50/p99/max", "missed", "floor p50/p99 us", "IR age p99", "peak F (N)",
             "coupling", "IR kB/s");
  for (const nlohmann::json& c : clients)
    fmt::print("{:<10} {:>8.1f} {:>22} {:>8.0f} {:>18} {:>9.2f} ms {:>12.3f} {:>10.3f} {:>12.1f}\n",
               c.value("user", "?"), number(c, {"haptic_rate_hz"}),
               fmt::format("{:.0f}/{:.0f}/{:.0f}", number(c, {"period_us", "p50"}),
                           number(c, {"period_us", "p99"}), number(c, {"period_us", "max"})),
               number(c, {"missed_deadlines"}),
               fmt::format("{:.0f}/{:.0f}", number(c, {"timer_floor", "period_us", "p50"}),
                           number(c, {"timer_floor", "period_us", "p99"})),
               number(c, {"ir_age_ms", "p99"}), number(c, {"force_n", "peak"}),
               number(c, {"coupling_n", "peak"}), number(c, {"ir", "bytes_per_s"}) / 1000);
  fmt::print("\n{:<11} {:<26} {:<28} {}\n", "who", "criterion", "value", "healthy if");
  for (const HealthCriterion& c : verdict.criteria)
    fmt::print("{:<11} {:<26} {:<28} {}{}\n", c.who, c.what, c.value, c.threshold,
               c.ok ? "" : "   <- UNHEALTHY");
  for (const std::string& note : verdict.notes) fmt::print("note: {}\n", note);
  if (verdict.problems.empty()) {
    fmt::print("\nhealthy\n");
  } else {
    fmt::print("\nUNHEALTHY:\n");
    for (const std::string& p : verdict.problems) fmt::print("  - {}\n", p);
  }
  if (!out.empty()) {
    if (out.has_parent_path()) std::filesystem::create_directories(out.parent_path());
    AtomicFile file(out);
    file.write(verdict.report.dump(2));
    file.commit();
    fmt::print("report: {}\n", out.string());
  }
  return verdict.problems.empty() ? 0 : 3;
}

LabCommand add_summarize_command(CLI::App& lab) {
  struct SummarizeCommandLine {
    std::filesystem::path server, out;
    std::vector<std::filesystem::path> clients;
  };
  auto line = std::make_shared<SummarizeCommandLine>();
  CLI::App* command = lab.add_subcommand("summarize",
                                         "Merge a session's server and client reports, print a "
                                         "table and judge its health (exit 3 if unhealthy)");
  command->add_option("--server-report", line->server, "The server's --report")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("--client-report", line->clients, "A client's --report (repeat)")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("--out", line->out, "Write the merged report here");
  return {command, [line] { return run_summarize(line->server, line->clients, line->out); }};
}

}  // namespace cohaptic
