// The server's simulation loop (server/simulation_loop.h) and what it does about failing
// steps, with the real Simulation on a cube.
//
// How a step is made to fail: --step-nodes asks the loop to hold the N surface nodes
// nearest a pressing tool outside every user's patch. With N equal to the number of
// movable surface nodes, the patch's nodes leave fewer than N to choose from, and every
// step in which a tool presses throws (nearest_surface_nodes: "N boundary nodes asked for,
// but the surface has only M"). No load-time check can refuse this N, since the patch
// depends on where the tool touches: it is a real failure a user can cause, with the real
// Simulation, not a mock.
//   - StepFailures logs the first failure and then at most one line a second, whose counts
//     add up to every failure; it ends the session at the 100th failure in a row;
//   - the loop in process: a pressing tool makes it fail 100 steps in a row and stop with
//     the cause; it slept to each deadline meanwhile (100 steps take >= 99 periods); it
//     released the tools; with fewer step nodes the same loop steps on and fills each
//     step's outbox (P0: one force per step for the known tool; P1: its IRs, keep-alives);
//   - P1's IRs go as compliance rows (must arrive), generation 1 again for each new user of
//     a slot, even one that joins between two steps after another left;
//   - the real server program: a client pressing makes the server end the session on its
//     own, with a clear message, a goodbye to the client, a report, few log lines and
//     exit status 1.
#include <array>
#include <gtest/gtest.h>
#include <signal.h>

#include <fmt/format.h>

#include <algorithm>
#include <mutex>

#include <chrono>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <thread>

#include "common/fem/dof_map.h"
#include "common/ir/client_condensation.h"
#include "common/ir/evaluate_force.h"
#include "common/util/monotonic_clock.h"
#include "proto/wire/ir_convert.h"
#include "proto/wire/ir_stream.h"
#include "proto/wire/header.h"
#include "server/simulation_loop.h"
#include "server/step_failures.h"
#include "support/cube_scene.h"
#include "support/process.h"

namespace cohaptic {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

int movable_surface_node_count(const Model& model) {
  const ElasticBody& body = single_elastic_body(model);
  int count = 0;
  for (int node : body.surface.nodes)
    count += body.dofs.fixed_axes[static_cast<std::size_t>(node)] != kAllAxes;
  return count;
}

// ---- pacing ----

TEST(LoopStatistics, TheStepRateCountsFromTheFirstStepNotFromTheServersStart) {
  // A scene that took 10 s to load, then 100 steps of 1 ms back to back: 1 kHz, not 10 Hz.
  LoopStatistics statistics;
  StepFigures step;
  step.duration_ns = 1'000'000;
  for (int k = 1; k <= 100; ++k) statistics.record_step(step, 10.0 + 1e-3 * k);
  const LoopSummary summary = statistics.summary();
  EXPECT_NEAR(summary.rate_hz(), 1000.0, 1e-6);
  EXPECT_NEAR(summary.elapsed_s, 10.1, 1e-12);
  EXPECT_EQ(LoopSummary{}.rate_hz(), 0.0) << "no step yet";
}

TEST(StepFailures, LogsTheFirstThenOneLineASecondWhoseCountsAddUpAndEndsAfterAHundredInARow) {
  StepFailures failures;
  std::vector<std::string> lines;
  std::int64_t now = 5'000'000'000;
  // A flapping error: 3 s of one failure every 2 ms, with a success in between.
  for (int i = 0; i < 1500; ++i, now += 2'000'000) {
    if (auto line = failures.failed(now, "degenerate contact")) lines.push_back(*line);
    failures.succeeded();
  }
  EXPECT_FALSE(failures.limit_reached());
  EXPECT_EQ(failures.total(), 1500u);
  ASSERT_EQ(lines.size(), 3u);  // at 0 s, 1 s and 2 s
  EXPECT_EQ(lines[0], "simulation step failed, tools released: degenerate contact");
  std::uint64_t logged = 1;
  const std::regex counted(R"(failed (\d+) times since the last report \(1 in a row\))");
  for (std::size_t i = 1; i < lines.size(); ++i) {
    std::smatch match;
    ASSERT_TRUE(std::regex_search(lines[i], match, counted)) << lines[i];
    logged += std::stoull(match[1]);
  }
  // The failures after the last line are counted for the next one: 499 of them.
  EXPECT_EQ(logged + 499, failures.total());

  // A run of failures in a row ends the session at the limit.
  for (int i = 0; i < kMaxConsecutiveStepFailures - 1; ++i, now += 1'000'000) {
    failures.failed(now, "stuck");
    EXPECT_FALSE(failures.limit_reached());
  }
  failures.failed(now, "stuck");
  EXPECT_TRUE(failures.limit_reached());
  EXPECT_EQ(failures.consecutive(), kMaxConsecutiveStepFailures);
  EXPECT_EQ(failures.last_error(), "stuck");
}

// A step takes only the newest sample, so presses are counted as samples arrive: a press
// and release both between two takes is one press; a button held across takes is one press
// (in the take after it went down); a reordered older sample changes nothing.
TEST(ToolInputs, APressBetweenTwoTakesIsCountedOnceAndAHeldButtonOnce) {
  ToolInputs tools{1};
  std::vector<ToolInput> taken;
  tools.join(0);
  const Eigen::Vector3d at = Eigen::Vector3d::Zero();
  std::int64_t t = 1;
  const auto sample = [&](std::uint32_t buttons) {
    return tools.update(0, true, at, buttons, t++, 0);
  };
  for (const std::uint32_t buttons : {0u, 0b10u, 0b10u, 0u})
    sample(buttons);  // button 1 pressed and released in a burst
  tools.take(taken);
  EXPECT_EQ(taken[0].buttons, 0u);
  EXPECT_EQ(taken[0].pressed, 0b10u);
  tools.take(taken);
  EXPECT_EQ(taken[0].pressed, 0u) << "counted once";
  sample(0b1);
  tools.take(taken);
  EXPECT_EQ(taken[0].pressed, 0b1u);
  for (int k = 0; k < 2; ++k) sample(0b1);
  tools.take(taken);
  EXPECT_EQ(taken[0].pressed, 0u) << "held, not pressed again";
  EXPECT_FALSE(tools.update(0, true, at, 0b100, 1, 0)) << "an older sample";
  tools.take(taken);
  EXPECT_EQ(taken[0].pressed, 0u);
}

// ---- the loop, in process ----

struct LoopRig {
  testing::CubeRig cube;
  ServeOptions options;
  ToolInputs tools{2};
  LoopStatistics statistics;
  explicit LoopRig(int step_nodes, ServeProtocol protocol = ServeProtocol::p1) : cube(soft_cube()) {
    options.step_nodes = step_nodes;
    options.protocol = protocol;
    options.sim_rate_hz = 200;
    options.client_timeout_s = 3600;  // the one sample below stays fresh
    tools.join(0);
    // Slot 0 presses 2 mm into the top face; slot 1 stays away.
    tools.update(0, true, Eigen::Vector3d(0.003, 0.002, -0.002), 0, 1, monotonic_now_ns());
  }
  static testing::CubeSceneOptions soft_cube() {
    testing::CubeSceneOptions options;
    options.divisions = 6;
    options.youngs_modulus = 2.0e4;
    return options;
  }
};

// Runs `loop` until it stops itself or `limit` passes; returns its result and the outboxes
// (the steps' and the IR encoder's, in the order handed over).
std::pair<std::optional<std::string>, std::vector<Outbox>> run_for(
    SimulationLoop& loop, std::chrono::milliseconds limit) {
  std::atomic<bool> running{true};
  std::thread watchdog([&] {
    const auto end = std::chrono::steady_clock::now() + limit;
    while (running && std::chrono::steady_clock::now() < end) std::this_thread::sleep_for(5ms);
    running = false;
  });
  std::vector<Outbox> outboxes;
  std::mutex handed_over;  // the simulation thread and the encoder's both hand over
  std::optional<std::string> stopped = loop.run(running, [&](Outbox&& outbox) {
    std::lock_guard lock(handed_over);
    outboxes.push_back(std::move(outbox));
  });
  running = false;
  watchdog.join();
  return {stopped, outboxes};
}

TEST(SimulationLoop, AStepThatKeepsFailingEndsTheLoopAfterAHundredPacedSteps) {
  LoopRig rig(0);
  rig.options.step_nodes = movable_surface_node_count(*rig.cube.model);
  SimulationLoop loop(*rig.cube.model, std::array{rig.cube.columns.get()}, rig.options, rig.tools,
                      rig.statistics, nullptr, nullptr, nullptr, monotonic_now_ns());
  const auto start = std::chrono::steady_clock::now();
  const auto [stopped, outboxes] = run_for(loop, 20s);
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_TRUE(stopped.has_value()) << "the loop did not stop on its own";
  EXPECT_NE(stopped->find("failed 100 steps in a row"), std::string::npos) << *stopped;
  EXPECT_NE(stopped->find("boundary nodes asked for"), std::string::npos) << *stopped;
  EXPECT_TRUE(outboxes.empty());
  const LoopSummary summary = rig.statistics.summary();
  EXPECT_EQ(summary.failed_steps, static_cast<std::uint64_t>(kMaxConsecutiveStepFailures));
  EXPECT_EQ(summary.max_consecutive_failures, kMaxConsecutiveStepFailures);
  EXPECT_EQ(summary.steps, 0u);
  // Each failed step slept to its deadline: 100 steps at 200 Hz span at least 99 periods.
  // (A loop that skipped its sleep would fail them all within a few milliseconds.)
  std::printf("  100 failing steps at 200 Hz took %.3f s\n", elapsed_s);
  EXPECT_GE(elapsed_s, 99 / rig.options.sim_rate_hz);
}

TEST(SimulationLoop, StepsOnWithFewerStepNodesAndFillsEachStepsOutbox) {
  // P0: every step sends the known tool's force, and only to its slot.
  {
    LoopRig rig(10, ServeProtocol::p0);
    SimulationLoop loop(*rig.cube.model, std::array{rig.cube.columns.get()}, rig.options, rig.tools,
                        rig.statistics, nullptr, nullptr, nullptr, monotonic_now_ns());
    const auto [stopped, outboxes] = run_for(loop, 400ms);
    EXPECT_FALSE(stopped.has_value()) << *stopped;
    const LoopSummary summary = rig.statistics.summary();
    EXPECT_EQ(summary.failed_steps, 0u);
    EXPECT_GT(summary.steps, 5u);
    ASSERT_EQ(outboxes.size(), summary.steps);
    for (const Outbox& outbox : outboxes) {
      EXPECT_TRUE(outbox.irs.empty());
      ASSERT_EQ(outbox.datagrams.size(), 1u);
      EXPECT_EQ(outbox.datagrams[0].slot, 0);
      EXPECT_TRUE(outbox.datagrams[0].message.has_force());
    }
    EXPECT_EQ(summary.forces_sent, summary.steps);
    EXPECT_GT(outboxes.back().datagrams[0].message.force().force().z(), 0)
        << "the pressed surface pushes back up";
  }
  // P1: the first step builds slot 0's IR, which the encoder hands over in an outbox of its
  // own; keep-alives follow in the steps'.
  {
    LoopRig rig(10, ServeProtocol::p1);
    SimulationLoop loop(*rig.cube.model, std::array{rig.cube.columns.get()}, rig.options, rig.tools,
                        rig.statistics, nullptr, nullptr, nullptr, monotonic_now_ns());
    const auto [stopped, outboxes] = run_for(loop, 400ms);
    EXPECT_FALSE(stopped.has_value());
    const auto first_ir = std::find_if(outboxes.begin(), outboxes.end(),
                                       [](const Outbox& o) { return !o.irs.empty(); });
    ASSERT_NE(first_ir, outboxes.end());
    ASSERT_EQ(first_ir->irs.size(), 1u);
    EXPECT_TRUE(first_ir->datagrams.empty()) << "an IR's outbox holds IRs only";
    EXPECT_EQ(first_ir->irs[0].slot, 0);
    // The cube's IRs are compliance rows: they travel in the user's zstd stream.
    EXPECT_TRUE(first_ir->irs[0].message.has_compressed_ir());
    wire::IrStreamReader stream;
    std::size_t keep_alives = 0, irs = 0, ir_bytes = 0;
    for (const Outbox& outbox : outboxes) {
      irs += outbox.irs.size();
      for (const auto& ir : outbox.irs) {
        ir_bytes += ir.message.compressed_ir().ByteSizeLong();
        EXPECT_EQ(stream.open(ir.message.compressed_ir()).fem().rows_generation(),
                  ir.message.compressed_ir().index());
      }
      for (const auto& datagram : outbox.datagrams) {
        EXPECT_EQ(datagram.slot, 0);
        keep_alives += datagram.message.has_keep_alive();
      }
    }
    EXPECT_EQ(irs, rig.statistics.summary().irs_sent);
    EXPECT_EQ(ir_bytes, rig.statistics.summary().ir_bytes_sent) << "the bytes as they travel";
    EXPECT_GE(keep_alives, 2u);
  }
}

// P1 sends a condensed FEM IR as compliance rows, generation 1 first, as a must-arrive
// frame in the user's zstd stream; a new user of the slot starts at generation 1 again, and
// a stream of its own, even when the old one left and the new one joined between two steps.
// A client opens and completes each.
TEST(SimulationLoop, SendsComplianceRowsAndStartsEachNewUserOfASlotAfresh) {
  LoopRig rig(0, ServeProtocol::p1);
  SimulationLoop loop(*rig.cube.model, std::array{rig.cube.columns.get()}, rig.options, rig.tools,
                      rig.statistics, nullptr, nullptr, nullptr, monotonic_now_ns());
  const auto first_ir = [&](const Eigen::Vector3d& tool, std::int64_t sample_time) {
    rig.tools.update(0, true, tool, 0, sample_time, monotonic_now_ns());
    for (int step = 0; step < 20; ++step) {
      Outbox outbox = loop.step(monotonic_now_ns());
      if (!outbox.irs.empty()) return outbox.irs.front();
    }
    ADD_FAILURE() << "no IR in 20 steps";
    return ToSlot<wire::Control>{};
  };
  wire::IrStreamReader stream;
  const auto open = [&stream](const ToSlot<wire::Control>& sent) {
    EXPECT_TRUE(sent.message.has_compressed_ir());
    return stream.open(sent.message.compressed_ir());
  };
  const ToSlot<wire::Control> first = first_ir(Eigen::Vector3d(0.003, 0.002, -0.002), 2);
  EXPECT_TRUE(first.must_arrive);
  const wire::IntermediateRepresentation first_sent = open(first);
  EXPECT_EQ(first_sent.fem().rows_generation(), 1u);
  const ToSlot<wire::Control> second = first_ir(Eigen::Vector3d(-0.03, 0.02, -0.002), 3);
  const wire::IntermediateRepresentation second_sent = open(second);
  EXPECT_EQ(second_sent.fem().rows_generation(), 2u);
  ClientCondensation client;
  for (const wire::IntermediateRepresentation* sent : {&first_sent, &second_sent}) {
    IntermediateRepresentation ir = wire::from_wire(*sent);
    client.complete(condensed_fem(ir));
    EXPECT_NO_THROW(prepare_ir(ir));
  }
  rig.tools.release(0);
  rig.tools.join(0);
  const ToSlot<wire::Control> again = first_ir(Eigen::Vector3d(0.02, -0.02, -0.002), 1);
  EXPECT_EQ(again.message.compressed_ir().index(), 1u) << "the new user's stream starts afresh";
  const wire::IntermediateRepresentation again_sent = open(again);
  EXPECT_EQ(again_sent.fem().rows_generation(), 1u) << "the new user holds nothing";
  ClientCondensation newcomer;
  IntermediateRepresentation ir = wire::from_wire(again_sent);
  newcomer.complete(condensed_fem(ir));
  EXPECT_NO_THROW(prepare_ir(ir));
}

// With B truncation too the server sends compliance rows: the IR lists the held nodes it
// leaves out, and a client completes it over all of them.
TEST(SimulationLoop, SendsComplianceRowsUnderBTruncation) {
  LoopRig rig(60);
  rig.cube.model->scene.haptic.boundary_truncation = 0.2;
  SimulationLoop loop(*rig.cube.model, std::array{rig.cube.columns.get()}, rig.options, rig.tools,
                      rig.statistics, nullptr, nullptr, nullptr, monotonic_now_ns());
  std::vector<ToSlot<wire::Control>> sent;
  for (int step = 0; step < 40 && sent.size() < 2; ++step) {
    if (step == 20)
      rig.tools.update(0, true, Eigen::Vector3d(-0.03, 0.02, -0.002), 0, 2, monotonic_now_ns());
    Outbox outbox = loop.step(monotonic_now_ns());
    for (ToSlot<wire::Control>& ir : outbox.irs) sent.push_back(std::move(ir));
  }
  ASSERT_FALSE(sent.empty());
  wire::IrStreamReader stream;
  ClientCondensation client;
  for (const ToSlot<wire::Control>& ir : sent) {
    EXPECT_TRUE(ir.must_arrive);
    ASSERT_TRUE(ir.message.has_compressed_ir()) << "rows travel in the user's stream";
    const wire::IntermediateRepresentation message = stream.open(ir.message.compressed_ir());
    const wire::CondensedFem& fem = message.fem();
    EXPECT_GT(fem.rows_generation(), 0u);
    EXPECT_GT(fem.truncated_node_ids_size(), 0)
        << "the step-delay nodes far from the tool are left out";
    IntermediateRepresentation completed = wire::from_wire(message);
    client.complete(condensed_fem(completed));
    EXPECT_EQ(condensed_fem(completed).m_tilde.cols(), static_cast<Eigen::Index>(fem.m_cols()));
    EXPECT_NO_THROW(prepare_ir(completed));
  }
}

// ---- the real server program ----

// A switch of the served condition takes effect at the next step: the held nodes and the
// protocol change there, the outbox tells the users, and a switch to P1 sends the user's IR
// in the same outbox as, and after, the announcement (its client changes over with it).
TEST(SimulationLoop, ASwitchedConditionChangesHeldNodesAndProtocolAtTheNextStep) {
  LoopRig rig(10, ServeProtocol::p0);
  ServedCondition held_p0, free_p1;
  held_p0.name = "A";
  held_p0.protocol = ServeProtocol::p0;
  held_p0.step_nodes = 10;
  free_p1.name = "B";
  free_p1.protocol = ServeProtocol::p1;
  ConditionSwitch conditions({held_p0, free_p1});
  SimulationLoop loop(*rig.cube.model, std::array{rig.cube.columns.get()}, rig.options, rig.tools,
                      rig.statistics, nullptr, nullptr, nullptr, monotonic_now_ns(), &conditions);
  const auto forces = [](const Outbox& outbox) {
    return std::count_if(outbox.datagrams.begin(), outbox.datagrams.end(),
                         [](const ToSlot<wire::Datagram>& d) { return d.message.has_force(); });
  };
  for (int step = 0; step < 5; ++step) {
    const Outbox outbox = loop.step(monotonic_now_ns());
    EXPECT_FALSE(outbox.protocol_switch.has_value());
    EXPECT_TRUE(outbox.irs.empty()) << "P0 sends no IR";
    EXPECT_EQ(forces(outbox), 1);
  }
  EXPECT_EQ(rig.statistics.summary().max_boundary_nodes, 10);

  conditions.serve("B");
  const Outbox switched = loop.step(monotonic_now_ns());
  ASSERT_TRUE(switched.protocol_switch.has_value());
  EXPECT_EQ(*switched.protocol_switch, wire::P1);
  EXPECT_EQ(forces(switched), 0);
  ASSERT_EQ(switched.irs.size(), 1u) << "the user's IR, announced before it";
  wire::IrStreamReader stream;
  IntermediateRepresentation ir =
      wire::from_wire(stream.open(switched.irs[0].message.compressed_ir()));
  const CondensedFemIr& fem = condensed_fem(ir);
  EXPECT_EQ(fem.node_ids.size(), static_cast<std::size_t>(fem.row_node_count))
      << "B holds no nodes, from the step it took effect";
  EXPECT_TRUE(fem.truncated_node_ids.empty());
  for (int step = 0; step < 5; ++step) {
    const Outbox outbox = loop.step(monotonic_now_ns());
    EXPECT_FALSE(outbox.protocol_switch.has_value());
    EXPECT_EQ(forces(outbox), 0);
  }

  conditions.serve("A");
  const Outbox back = loop.step(monotonic_now_ns());
  ASSERT_TRUE(back.protocol_switch.has_value());
  EXPECT_EQ(*back.protocol_switch, wire::P0);
  EXPECT_EQ(forces(back), 1) << "P0's forces from the step the switch took effect";
  EXPECT_TRUE(back.irs.empty());
}

TEST(ServerProgram, EndsTheSessionWithAnErrorWhenEveryStepFails) {
  const fs::path dir = testing::scratch_directory("server-step-failures");
  testing::CubeSceneOptions scene = LoopRig::soft_cube();
  scene.divisions = 8;
  std::ofstream(dir / "cube.yaml") << testing::cube_scene_yaml(scene);
  const int step_nodes = movable_surface_node_count(*testing::CubeRig(scene).model);
  std::ofstream(dir / "press.yaml") << R"(
units: mm
start: [3, 2, 6]
segments:
  - {move_to: [3, 2, 0.5], speed: 20}
  - {press: 3, speed: 5, direction: [0, 0, -1]}
  - {hold: 4}
  - {release: 3, speed: 5}
)";
  testing::ChildProcess server(
      testing::server_program(),
      {"--scene", (dir / "cube.yaml").string(), "--listen", "127.0.0.1:0", "--step-nodes",
       std::to_string(step_nodes), "--sim-rate-hz", "100", "--duration", "60", "--report",
       (dir / "server.json").string(), "--no-disk-cache"},
      dir / "server.log");
  ASSERT_TRUE(server.wait_for_log("listening on", 20s)) << server.log_text();
  testing::ChildProcess client(
      testing::client_program(),
      {"--server", fmt::format("127.0.0.1:{}", testing::listening_port(server.log_text())),
       "--user", "alice", "--device", "script:" + (dir / "press.yaml").string()},
      dir / "client.log");
  const std::optional<int> status = server.wait(30s);
  ASSERT_TRUE(status.has_value()) << "the server did not end the session\n" << server.log_text();
  EXPECT_EQ(*status, 1) << server.log_text();
  const std::string log = server.log_text();
  EXPECT_NE(log.find("the simulation failed 100 steps in a row, the last with: "),
            std::string::npos)
      << log;
  EXPECT_NE(log.find("boundary nodes asked for"), std::string::npos) << log;
  // About a second of failures at 100 Hz: the first line, perhaps one more.
  std::size_t lines = 0;
  for (std::size_t at = log.find("simulation step failed"); at != std::string::npos;
       at = log.find("simulation step failed", at + 1))
    ++lines;
  EXPECT_GE(lines, 1u);
  EXPECT_LE(lines, 3u) << log;
  std::ifstream in(dir / "server.json");
  const nlohmann::json report = nlohmann::json::parse(in)["server"];
  EXPECT_EQ(report["failed_steps"]["count"], kMaxConsecutiveStepFailures);
  EXPECT_EQ(report["failed_steps"]["max_in_a_row"], kMaxConsecutiveStepFailures);
  EXPECT_NE(
      report["failed_steps"]["last_error"].get<std::string>().find("boundary nodes asked for"),
      std::string::npos);
  // The client was told why, and is on its own again (it keeps trying to reconnect).
  EXPECT_TRUE(client.wait_for_log("server said goodbye: the server's simulation failed", 10s))
      << client.log_text();
  client.signal(SIGINT);
  EXPECT_TRUE(client.wait(10s).has_value());
}

}  // namespace
}  // namespace cohaptic
