// The demo's verdict (cohaptic-lab summarize): each criterion on hand-made reports.
#include <gtest/gtest.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <string>

#include "lab/session_summary.h"

namespace cohaptic {
namespace {

nlohmann::json healthy_server() {
  return {
      {"server",
       {{"steps", 5000}, {"datagrams", {{"rejected", 0}}}, {"control_frames", {{"rejected", 0}}}}}};
}

// A client that did everything right: 16,000 ticks at 1 kHz, IRs received, coupled.
nlohmann::json healthy_client(const std::string& user) {
  return {{"user", user},
          {"ticks", 16000},
          {"haptic_rate_hz", 999.9},
          {"rate_setting_hz", 1000.0},
          {"protocol", "P1"},
          {"ir", {{"received", 100}}},
          {"force_n", {{"peak", 0.5}}},
          {"coupling_n", {{"peak", 0.4}}},
          {"non_finite_ticks", 0},
          {"datagrams", {{"rejected", 0}}},
          {"period_us", {{"p50", 1000.0}, {"p99", 1030.0}}},
          {"missed_deadlines", 0},
          {"timer_floor", {{"missed_deadlines", 0}, {"period_us", {{"p99", 1025.0}}}}}};
}

bool mentions(const std::vector<std::string>& lines, const std::string& text) {
  return std::any_of(lines.begin(), lines.end(),
                     [&](const std::string& l) { return l.find(text) != std::string::npos; });
}

TEST(SessionSummary, TwoGoodClientsAreHealthy) {
  const SessionVerdict verdict =
      summarize_session(healthy_server(), {healthy_client("a"), healthy_client("b")});
  EXPECT_TRUE(verdict.problems.empty()) << verdict.problems.front();
  EXPECT_TRUE(verdict.report["healthy"].get<bool>());
}

TEST(SessionSummary, MissedDeadlinesAreTheLoopsOnlyBeyondWhatTheBareTimerMissed) {
  // 40 of 16,000 (0.25 %) with a floor that missed nothing: the loop's fault.
  nlohmann::json late = healthy_client("a");
  late["missed_deadlines"] = 40;
  SessionVerdict verdict = summarize_session(healthy_server(), {late, healthy_client("b")});
  EXPECT_TRUE(mentions(verdict.problems, "a: 40 missed deadlines"))
      << verdict.report["problems"].dump();

  // The same 40 while the bare timer missed 30: the machine stalled; a note, not a failure.
  late["timer_floor"]["missed_deadlines"] = 30;
  verdict = summarize_session(healthy_server(), {late, healthy_client("b")});
  EXPECT_TRUE(verdict.problems.empty()) << verdict.report["problems"].dump();
  EXPECT_TRUE(mentions(verdict.notes, "timer floor missed 30"));

  // 60 against a floor of 30: 30 (0.19 %) are the loop's own.
  late["missed_deadlines"] = 60;
  verdict = summarize_session(healthy_server(), {late, healthy_client("b")});
  EXPECT_TRUE(mentions(verdict.problems, "a: 60 missed deadlines"));

  // A session of 2,300 ticks on a stalling machine: 38 against the floor's 35 is counting
  // noise (three times the root of 35 is 17.7), though over 0.1 % of the ticks; 60 is not.
  late["ticks"] = 2300;
  late["timer_floor"]["missed_deadlines"] = 35;
  late["missed_deadlines"] = 38;
  verdict = summarize_session(healthy_server(), {late, healthy_client("b")});
  EXPECT_TRUE(verdict.problems.empty()) << verdict.report["problems"].dump();
  late["missed_deadlines"] = 60;
  verdict = summarize_session(healthy_server(), {late, healthy_client("b")});
  EXPECT_TRUE(mentions(verdict.problems, "a: 60 missed deadlines"))
      << verdict.report["problems"].dump();
}

// A client's floors, one per CPU, as cohaptic-client reports them (client/timer_floors.h): the
// host held CPU 1 back for 100 ms, and that CPU's floor missed what the loop did.
TEST(SessionSummary, MissedDeadlinesNameTheHostsStealTimePerCpu) {
  nlohmann::json stalled = healthy_client("a");
  stalled["missed_deadlines"] = 99;
  stalled["timer_floor"]["missed_deadlines"] = 100;
  stalled["timer_floor"]["cpus"] = {
      {{"cpu", 0}, {"missed_deadlines", 0}, {"host_steal_ms", 0.0}},
      {{"cpu", 1}, {"missed_deadlines", 100}, {"host_steal_ms", 100.0}}};
  SessionVerdict verdict = summarize_session(healthy_server(), {stalled, healthy_client("b")});
  EXPECT_TRUE(verdict.problems.empty()) << verdict.report["problems"].dump();
  EXPECT_TRUE(mentions(
      verdict.notes,
      "a: 99 missed deadlines (timer floor missed 100; host steal time: CPU 0 0 ms, CPU 1 100 ms)"))
      << verdict.report["notes"].dump();
  stalled["timer_floor"]["missed_deadlines"] = 0;  // no floor saw it: the loop's own
  verdict = summarize_session(healthy_server(), {stalled, healthy_client("b")});
  EXPECT_TRUE(mentions(verdict.problems,
                       "the bare timer floor 0; host steal time: CPU 0 0 ms, CPU 1 100 ms"))
      << verdict.report["problems"].dump();
}

// 2,000 ticks lost of 16,000 (a rate of 889 Hz): the loop's own when the bare timer floor
// kept its deadlines, the machine's (a note naming the host's steal) when it missed as many.
TEST(SessionSummary, ALowHapticRateIsAProblemUnlessTheTimerFloorLostAsManyTicks) {
  nlohmann::json slow = healthy_client("a");
  slow["haptic_rate_hz"] = 888.9;
  slow["missed_deadlines"] = 2000;
  SessionVerdict verdict = summarize_session(healthy_server(), {slow, healthy_client("b")});
  EXPECT_TRUE(mentions(verdict.problems, "a: haptic rate 888.9 Hz, below 95 % of 1000 Hz"))
      << verdict.report["problems"].dump();
  slow["timer_floor"]["missed_deadlines"] = 1990;
  slow["timer_floor"]["cpus"] = {
      {{"cpu", 0}, {"missed_deadlines", 1990}, {"host_steal_ms", 1800.0}}};
  verdict = summarize_session(healthy_server(), {slow, healthy_client("b")});
  EXPECT_TRUE(verdict.problems.empty()) << verdict.report["problems"].dump();
  EXPECT_TRUE(mentions(verdict.notes,
                       "a: 2000 missed deadlines, so a haptic rate of 888.9 Hz, the machine's "
                       "(timer floor missed 1990; host steal time: CPU 0 1800 ms)"))
      << verdict.report["notes"].dump();
  // A host that stole half the session: the loop missed 1.0 % more than the floor (noise);
  // missing a tenth more is its own.
  slow["missed_deadlines"] = 2010;
  verdict = summarize_session(healthy_server(), {slow, healthy_client("b")});
  EXPECT_TRUE(verdict.problems.empty()) << verdict.report["problems"].dump();
  slow["missed_deadlines"] = 2190;
  verdict = summarize_session(healthy_server(), {slow, healthy_client("b")});
  EXPECT_TRUE(mentions(verdict.problems, "a: 2190 missed deadlines"))
      << verdict.report["problems"].dump();
}

TEST(SessionSummary, SlowPeriodIsAProblemUnlessTheTimerFloorIsAsSlow) {
  nlohmann::json slow = healthy_client("a");
  slow["period_us"]["p99"] = 1300.0;
  SessionVerdict verdict = summarize_session(healthy_server(), {slow, healthy_client("b")});
  EXPECT_TRUE(mentions(verdict.problems, "haptic period p99 1300 us"));
  slow["timer_floor"]["period_us"]["p99"] = 1250.0;
  verdict = summarize_session(healthy_server(), {slow, healthy_client("b")});
  EXPECT_TRUE(verdict.problems.empty()) << verdict.report["problems"].dump();
  EXPECT_TRUE(mentions(verdict.notes, "bare timer"));
  // A floor late by milliseconds (a host stalling its vCPUs): within a tenth of it.
  slow["timer_floor"]["period_us"]["p99"] = 7000.0;
  slow["period_us"]["p99"] = 7650.0;
  verdict = summarize_session(healthy_server(), {slow, healthy_client("b")});
  EXPECT_TRUE(verdict.problems.empty()) << verdict.report["problems"].dump();
  slow["period_us"]["p99"] = 7750.0;
  verdict = summarize_session(healthy_server(), {slow, healthy_client("b")});
  EXPECT_TRUE(mentions(verdict.problems, "more than 700 us above the timer floor (7000 us)"))
      << verdict.report["problems"].dump();
}

TEST(SessionSummary, EachFailedCriterionIsNamed) {
  nlohmann::json bad = healthy_client("a");
  bad["non_finite_ticks"] = 3;
  bad["haptic_rate_hz"] = 800.0;
  bad["coupling_n"]["peak"] = 0.01;
  bad["ir"]["received"] = 0;
  nlohmann::json server = healthy_server();
  server["server"]["datagrams"]["rejected"] = 7;
  const SessionVerdict verdict = summarize_session(server, {bad, healthy_client("b")});
  EXPECT_FALSE(verdict.report["healthy"].get<bool>());
  for (const char* text : {"a: non-finite forces", "a: haptic rate 800.0 Hz",
                           "a: nothing to compute forces from", "server: 7 datagrams rejected"})
    EXPECT_TRUE(mentions(verdict.problems, text))
        << text << " in " << verdict.report["problems"].dump();
  EXPECT_EQ(verdict.problems.size(), 4u) << verdict.report["problems"].dump();
  // Users far apart feel little of each other: the experiment's design, a note.
  EXPECT_TRUE(mentions(verdict.notes, "a: coupling peak 0.010 N"))
      << verdict.report["notes"].dump();
  EXPECT_TRUE(summarize_session(healthy_server(), {}).problems.size() == 1);
}

TEST(SessionSummary, FailedSimulationStepsMakeTheSessionUnhealthyNamingCountAndLastError) {
  nlohmann::json server = healthy_server();
  server["server"]["failed_steps"] = {{"count", 0}, {"max_in_a_row", 0}, {"last_error", ""}};
  EXPECT_TRUE(summarize_session(server, {healthy_client("a")}).problems.empty());

  server["server"]["failed_steps"] = {
      {"count", 12}, {"max_in_a_row", 4}, {"last_error", "contact solve: singular"}};
  const SessionVerdict verdict = summarize_session(server, {healthy_client("a")});
  EXPECT_FALSE(verdict.report["healthy"].get<bool>());
  ASSERT_EQ(verdict.problems.size(), 1u) << verdict.report["problems"].dump();
  EXPECT_TRUE(mentions(verdict.problems, "server: 12 simulation steps failed (4 in a row at most)"))
      << verdict.problems.front();
  EXPECT_TRUE(mentions(verdict.problems, "contact solve: singular")) << verdict.problems.front();
}

// What the users felt: a starved server, fades, the force limit and stale IRs each make the
// session unhealthy, naming the cause; each criterion is in the report with its threshold.
TEST(SessionSummary, AStarvedServerFadesTheForceLimitAndStaleIrsAreNamed) {
  nlohmann::json server = healthy_server();
  server["server"]["target_sim_rate_hz"] = 20.0;
  server["server"]["sim_rate_hz"] = 900.0;
  nlohmann::json client = healthy_client("a");
  client["ir_age_ms"] = {{"p50", 2.0}, {"p99", 12.0}, {"max", 180.0}, {"fade_after", 500.0}};
  client["fades"] = {{"count", 0}, {"total_s", 0.0}, {"longest_s", 0.0}};
  client["force_n"]["clamped_ticks"] = 16;  // 0.1 %
  SessionVerdict verdict = summarize_session(server, {client});
  EXPECT_TRUE(verdict.problems.empty()) << verdict.report["problems"].dump();
  const nlohmann::json& criteria = verdict.report["criteria"];
  const auto criterion = [&](const std::string& who, const std::string& what) {
    for (const nlohmann::json& c : criteria)
      if (c["who"] == who && c["criterion"] == what) return c;
    return nlohmann::json();
  };
  EXPECT_EQ(criterion("server", "simulation step rate")["threshold"], ">= 18.0 Hz")
      << criteria.dump();
  EXPECT_EQ(criterion("a", "IR age p99")["threshold"], "<= 200 ms")
      << criteria.dump();  // 4 steps at 20 Hz
  EXPECT_EQ(criterion("a", "IR age max")["value"], "180.0 ms") << criteria.dump();
  EXPECT_EQ(criterion("a", "force fades while pushing")["ok"], true) << criteria.dump();

  server["server"]["sim_rate_hz"] = 0.34;
  server["server"]["step_ms"] = {{"p99", 2900.0}, {"max", 3100.0}};
  client["fades"] = {{"count", 2}, {"total_s", 0.376}, {"longest_s", 0.3}};
  client["force_n"]["clamped_ticks"] = 17;
  client["ir_age_ms"]["p99"] = 201.0;
  client["ir_age_ms"]["max"] = 500.0;
  verdict = summarize_session(server, {client});
  EXPECT_FALSE(verdict.report["healthy"].get<bool>());
  for (const char* text :
       {"server: the simulation stepped at 0.3 Hz, below 90 % of its target 20 Hz: the server is "
        "starved",
        "a: the force faded 2 time(s) while pushing (376 ms in all, the longest 300 ms)",
        "a: 17 ticks (0.11 %) held at the force limit", "a: IR age p99 201.0 ms, above 200 ms",
        "a: IR age reached 500 ms, the age at which the force fades"})
    EXPECT_TRUE(mentions(verdict.problems, text))
        << text << " in " << verdict.report["problems"].dump();
  EXPECT_EQ(verdict.problems.size(), 5u) << verdict.report["problems"].dump();
  server["server"]["injected"] = {
      {"sim_rate_hz", 0.34}};  // a study capped it: the users feel it all the same
  verdict = summarize_session(server, {client});
  EXPECT_TRUE(
      mentions(verdict.problems, "below 90 % of its target 20 Hz: capped by --sim-rate-hz 0.34"))
      << verdict.report["problems"].dump();

  // Shift delay injected on the links lengthens the IR age the session is held to.
  server["server"]["sim_rate_hz"] = 900.0;
  server["server"]["injected"] = {{"shift_delay_ms", 50.0}, {"jitter_ms", 0.0}};
  client["fades"]["count"] = 0;
  client["force_n"]["clamped_ticks"] = 0;
  client["ir_age_ms"]["max"] = 400.0;
  verdict = summarize_session(server, {client});
  EXPECT_TRUE(verdict.problems.empty()) << verdict.report["problems"].dump();
}

}  // namespace
}  // namespace cohaptic
