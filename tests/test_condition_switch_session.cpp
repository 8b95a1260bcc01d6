// A session that switches conditions while it runs, as a paired comparison does: a real
// cohaptic-server serving two conditions (P0 with held nodes; P1 with a shift delay) and a
// control socket, a real cohaptic-client pressing and holding, and an experimenter's
// switches over the socket. Each switch takes effect in the server (held nodes, link delay,
// protocol) and in the client (its protocol, without a fade), is recorded, and both
// recordings re-run bit for bit.
#include <gtest/gtest.h>

#include <fmt/format.h>
#include <signal.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <thread>

#include "lab/control_client.h"
#include "lab/replay.h"
#include "proto/record/recording.h"
#include "support/csv_table.h"
#include "support/cube_scene.h"
#include "support/process.h"

namespace cohaptic {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

constexpr double kShiftMs = 25;
constexpr int kHeldNodes = 60;

double median(std::vector<double> values) {
  if (values.empty()) return std::nan("");
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2),
                   values.end());
  return values[values.size() / 2];
}

// Conditions A (P0, held nodes) and B (P1, shift delay) served to one scripted subject on
// the small cube, with a control socket, recorded in a scratch directory.
struct SwitchingSession {
  fs::path dir;
  std::unique_ptr<testing::ChildProcess> server, client;

  SwitchingSession(const std::string& name, const std::string& trajectory,
                   const std::vector<std::string>& server_extra, double client_s)
      : dir(testing::scratch_directory(name)) {
    std::ofstream(dir / "cube.yaml") << testing::cube_scene_yaml(testing::pressed_cube_options());
    std::ofstream(dir / "press.yaml") << trajectory;
    std::vector<std::string> arguments = {
        "--scene",        (dir / "cube.yaml").string(),
        "--listen",       "127.0.0.1:0",
        "--condensation", "naive",
        "--condition",    fmt::format("A:protocol=P0,step_nodes={}", kHeldNodes),
        "--condition",    fmt::format("B:protocol=P1,shift_ms={}", kShiftMs),
        "--control",      (dir / "control").string(),
        "--duration",     "60",
        "--record",       (dir / "server.mcap").string(),
        "--report",       (dir / "server.json").string()};
    arguments.insert(arguments.end(), server_extra.begin(), server_extra.end());
    server = std::make_unique<testing::ChildProcess>(testing::server_program(), arguments,
                                                     dir / "server.log");
    EXPECT_TRUE(testing::wait_for_output(*server, "listening on")) << server->log_text();
    const int port = testing::listening_port(server->log_text());
    client = std::make_unique<testing::ChildProcess>(
        testing::client_program(),
        std::vector<std::string>{
            "--server", fmt::format("127.0.0.1:{}", port), "--user", "subject", "--slot", "0",
            "--device", "script:" + (dir / "press.yaml").string(), "--duration",
            fmt::format("{:g}", client_s), "--record", (dir / "subject.mcap").string(), "--report",
            (dir / "subject.json").string()},
        dir / "subject.log");
    EXPECT_TRUE(testing::wait_for_output(*client, "haptic thread")) << client->log_text();
  }
  // Waits for the client's end, then stops the server: both exit 0.
  void finish() {
    EXPECT_EQ(client->wait(30s), 0) << client->log_text();
    server->signal(SIGINT);
    EXPECT_EQ(server->wait(30s), 0) << server->log_text();
  }
  // The conditions the server's recording marks as switched to, in order.
  std::vector<std::string> recorded_switches() const {
    std::vector<std::string> names;
    for (const record::SimulationStep& step : record::read_recording(dir / "server.mcap").steps)
      if (step.has_condition_switch()) names.push_back(step.condition_switch().name());
    return names;
  }
};

TEST(ConditionSwitchSession, EachSwitchTakesEffectInServerAndClientIsRecordedAndReplaysBitForBit) {
  SwitchingSession session("condition-switch", R"(
units: mm
start: [4, 3, 4]
segments:
  - {move_to: [4, 3, 0.5], speed: 20}
  - {press: 0.75, speed: 1.5, direction: [0, 0, -1]}
  - {hold: 5}
  - {release: 0.75, speed: 1.5}
)",
                           {}, 6.5);
  const fs::path& dir = session.dir;

  // The experimenter switches while the subject presses and holds: B, A, B, A by name, then
  // B as the next condition.
  ControlClient control(dir / "control");
  std::this_thread::sleep_for(1500ms);  // pressing by now
  const std::vector<std::string> switches = {"B", "A", "B", "A", "B"};
  for (std::size_t i = 0; i < switches.size(); ++i) {
    const nlohmann::json reply =
        i + 1 < switches.size() ? control.serve(switches[i]) : control.serve_next();
    EXPECT_EQ(reply.value("served", ""), switches[i]) << reply;
    EXPECT_EQ(reply.value("switches", 0u), i + 1) << reply;
    std::this_thread::sleep_for(700ms);
  }
  EXPECT_NE(control.ask({{"serve", "C"}}).value("error", "").find("no condition named 'C'"),
            std::string::npos);
  session.finish();
  ASSERT_FALSE(::testing::Test::HasFailure());

  // The server: each switch on the step it took effect, in order, with its settings; the
  // held nodes and the tool samples' delay follow the condition served.
  const record::Recording served = record::read_recording(dir / "server.mcap");
  std::vector<std::string> recorded;
  std::string condition = "A";
  std::map<std::string, std::vector<double>> sample_age_ms;
  std::map<std::string, std::set<std::uint32_t>> held;
  for (const record::SimulationStep& step : served.steps) {
    if (step.has_condition_switch()) {
      const record::ConditionSwitch& s = step.condition_switch();
      recorded.push_back(s.name());
      condition = s.name();
      EXPECT_EQ(s.protocol(), condition == "A" ? wire::P0 : wire::P1);
      EXPECT_EQ(s.injected().shift_delay_ms(), condition == "A" ? 0 : kShiftMs);
      EXPECT_EQ(s.injected().step_nodes(),
                condition == "A" ? static_cast<unsigned>(kHeldNodes) : 0u);
      continue;  // the step a switch took effect mixes both
    }
    if (step.pressing_slots_size() == 0) continue;
    held[condition].insert(step.boundary_nodes());
    for (const record::ToolInput& tool : step.tools())
      if (tool.known())
        sample_age_ms[condition].push_back(
            static_cast<double>(step.time_ns() - tool.sample_time_ns()) * 1e-6);
  }
  EXPECT_EQ(recorded, switches);
  EXPECT_EQ(session.recorded_switches(), switches);
  EXPECT_EQ(held["A"], (std::set<std::uint32_t>{kHeldNodes}))
      << "A holds its nodes whenever the tool presses";
  EXPECT_EQ(held["B"], (std::set<std::uint32_t>{0})) << "B holds none";
  const double age_a = median(sample_age_ms["A"]), age_b = median(sample_age_ms["B"]);
  std::printf(
      "  tool samples' age at the server (median): A %.1f ms, B %.1f ms (B's links delayed %g "
      "ms)\n",
      age_a, age_b, kShiftMs);
  EXPECT_GE(age_b, kShiftMs);
  EXPECT_LT(age_a, kShiftMs / 2);
  const nlohmann::json server_report = nlohmann::json::parse(std::ifstream(dir / "server.json"));
  EXPECT_EQ(server_report["server"]["condition_switches"], switches.size());
  std::vector<std::string> logged;
  double previous_s = 0;
  for (const nlohmann::json& made : server_report["server"]["switch_log"]) {
    logged.push_back(made["served"]);
    EXPECT_GT(made["time_s"].get<double>(), previous_s + 0.5) << "the switches came 0.7 s apart";
    previous_s = made["time_s"];
  }
  EXPECT_EQ(logged, switches);

  // The client: one change of protocol per switch, each without a fade.
  const nlohmann::json client_report = nlohmann::json::parse(std::ifstream(dir / "subject.json"));
  EXPECT_EQ(client_report["protocol_switches"], switches.size());
  EXPECT_EQ(client_report["fades"]["count"], 0) << "the force never lapsed";
  const record::Recording felt = record::read_recording(dir / "subject.mcap");
  std::size_t changes = 0;
  for (std::size_t i = 1; i < felt.ticks.size(); ++i)
    changes += felt.ticks[i].protocol() != felt.ticks[i - 1].protocol();
  EXPECT_EQ(changes, switches.size());

  for (const char* file : {"server.mcap", "subject.mcap"}) {
    const VerifyResult result = verify_recording(dir / file, SceneFileAccess{});
    EXPECT_TRUE(result.ok) << file << ": " << result.first_difference;
    EXPECT_GT(result.checked, 100u) << file;
  }
}

// A subject with one hand on the device switches with its button: each press serves the
// next condition, as a command on the control socket would.
TEST(ConditionSwitchSession, EachPressOfTheSwitchButtonServesTheNextCondition) {
  SwitchingSession session("button-switch", R"(
units: mm
start: [4, 3, 4]
segments:
  - {move_to: [4, 3, 0.5], speed: 20}
  - {press: 0.75, speed: 1.5, direction: [0, 0, -1]}
  - {hold: 1}
  - {hold: 0.2, buttons: 1}
  - {hold: 1}
  - {hold: 0.2, buttons: 1}
  - {hold: 1}
  - {release: 0.75, speed: 1.5}
)",
                           {"--switch-button", "0"}, 5);
  session.finish();
  ASSERT_FALSE(::testing::Test::HasFailure());
  EXPECT_EQ(session.recorded_switches(), (std::vector<std::string>{"B", "A"}));
  // From the CSV exports: each switch took effect within 50 ms after the server received
  // the sample in which the button went down, however the samples came.
  for (const char* file : {"server.mcap", "subject.mcap"}) {
    ReplayOptions export_csv;
    export_csv.file = session.dir / file;
    export_csv.export_csv = session.dir / (std::string(file) + "-csv");
    EXPECT_EQ(run_replay(export_csv), 0);
  }
  std::vector<double> pressed_s, switched_s;
  std::string before = "0";
  for (const testing::CsvRow& sample :
       testing::read_csv_table(session.dir / "server.mcap-csv" / "tool_samples.csv")) {
    if (sample.at("buttons") == "1" && before == "0")
      pressed_s.push_back(std::stod(sample.at("receive_time_s")));
    before = sample.at("buttons");
  }
  for (const testing::CsvRow& step :
       testing::read_csv_table(session.dir / "server.mcap-csv" / "steps.csv"))
    if (!step.at("condition_switch").empty()) switched_s.push_back(std::stod(step.at("time_s")));
  ASSERT_EQ(pressed_s.size(), 2u);
  ASSERT_EQ(switched_s.size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_GT(switched_s[k], pressed_s[k]);
    EXPECT_LT(switched_s[k], pressed_s[k] + 0.05);
  }
  int ticks_pressed = 0;
  for (const testing::CsvRow& tick :
       testing::read_csv_table(session.dir / "subject.mcap-csv" / "haptic.csv"))
    ticks_pressed += tick.at("buttons") == "1";
  EXPECT_NEAR(ticks_pressed, 2 * 200, 10) << "two presses of 0.2 s at 1 kHz";
  const nlohmann::json client_report =
      nlohmann::json::parse(std::ifstream(session.dir / "subject.json"));
  EXPECT_EQ(client_report["protocol_switches"], 2);
  EXPECT_EQ(client_report["fades"]["count"], 0);
  for (const char* file : {"server.mcap", "subject.mcap"}) {
    const VerifyResult result = verify_recording(session.dir / file, SceneFileAccess{});
    EXPECT_TRUE(result.ok) << file << ": " << result.first_difference;
  }
}

}  // namespace
}  // namespace cohaptic
