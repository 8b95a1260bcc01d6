// The mass-spring body on the server and through the IR: the sub-network an IR carries
// (its sections, rim and springs against the body's), the client's force against the
// server's whole network (bit for bit when the IR carries the whole network, within a
// bound for a sub-network), the client's force through the wire against the server's P0
// evaluation in lockstep (bit for bit), the IR rate, and SceneSimulation's assignment of
// users to the nearest of two bodies with epochs that keep rising.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>

#include "common/ir/build_mass_spring_ir.h"
#include "common/mass_spring/tube_network.h"
#include "common/model/model.h"
#include "common/model/scene_compliance.h"
#include "common/scene/load_scene.h"
#include "common/sim/mass_spring_simulation.h"
#include "common/sim/scene_simulation.h"
#include "common/util/error.h"
#include "proto/wire/ir_convert.h"
#include "support/test_meshes.h"

namespace cohaptic {
namespace {

bool same_bits(const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return std::memcmp(a.data(), b.data(), sizeof(double) * 3) == 0; }

const Model& noodle_model() {
  static const Model model = build_model(load_scene(testing::source_path("scenes/thin/noodle.yaml")));
  return model;
}

const MassSpringModel& noodle() { return std::get<MassSpringModel>(noodle_model().bodies.front()); }

// A node on the top of the tube in section `section`.
int top_node(const MassSpringModel& body, int section) {
  int best = kSectionNodes * section + 1;
  for (int k = 1; k <= kRingNodes; ++k)
    if (body.network.rest_positions(2, kSectionNodes * section + k) > body.network.rest_positions(2, best))
      best = kSectionNodes * section + k;
  return best;
}

TEST(MassSpringIr, CarriesTheSectionsAroundTheContactWithAHeldRim) {
  const MassSpringModel& body = noodle();
  const MassSpringState state = make_state(body.network);
  const int middle = body.section_count / 2;
  const MassSpringIr ir = build_mass_spring_ir(body, state, top_node(body, middle), 4);
  ASSERT_EQ(ir.node_count(), (2 * 4 + 1 + 2) * kSectionNodes);
  int held = 0;
  for (int i = 0; i < ir.node_count(); ++i) {
    const int section = body.section_of_node[static_cast<std::size_t>(ir.node_ids[static_cast<std::size_t>(i)])];
    const bool rim = std::abs(section - middle) == 5;
    EXPECT_EQ(ir.held[static_cast<std::size_t>(i)] != 0, rim) << "local node " << i;
    held += ir.held[static_cast<std::size_t>(i)];
    EXPECT_EQ(ir.positions.col(i), state.positions.col(ir.node_ids[static_cast<std::size_t>(i)]));
  }
  EXPECT_EQ(held, 2 * kSectionNodes);
  // Every spring of the body with both ends inside, and no other, with its parameters.
  std::map<std::pair<int, int>, const Spring*> body_springs;
  for (const Spring& s : body.network.springs) body_springs[{s.a, s.b}] = &s;
  std::size_t inside = 0;
  for (const Spring& s : body.network.springs) {
    const int a = body.section_of_node[static_cast<std::size_t>(s.a)], b = body.section_of_node[static_cast<std::size_t>(s.b)];
    inside += std::abs(a - middle) <= 5 && std::abs(b - middle) <= 5;
  }
  ASSERT_EQ(ir.springs.size(), inside);
  for (const Spring& s : ir.springs) {
    const Spring* original = body_springs.at({ir.node_ids[static_cast<std::size_t>(s.a)], ir.node_ids[static_cast<std::size_t>(s.b)]});
    EXPECT_EQ(s.stiffness, original->stiffness);
    EXPECT_EQ(s.rest_length, original->rest_length);
    EXPECT_EQ(s.damping, original->damping);
  }

  // At an end: no rim beyond it. Wider than the body: the whole network, nothing held.
  const MassSpringIr end = build_mass_spring_ir(body, state, top_node(body, 0), 4);
  EXPECT_EQ(end.node_count(), (4 + 1 + 1) * kSectionNodes);
  const MassSpringIr whole = build_mass_spring_ir(body, state, top_node(body, middle), body.section_count);
  EXPECT_EQ(whole.node_count(), body.network.node_count());
  EXPECT_EQ(whole.springs.size(), body.network.springs.size());
  EXPECT_EQ(whole.triangles.size(), body.network.triangles.size());
  for (std::uint8_t h : whole.held) EXPECT_EQ(h, 0);
}

TEST(MassSpringIr, CrossesTheWireBitForBitAndABadSpringIsRefusedByName) {
  const MassSpringModel& body = noodle();
  MassSpringState state = make_state(body.network);
  state.velocities.setRandom();
  IntermediateRepresentation ir;
  ir.epoch = 7;
  MassSpringIr sub = build_mass_spring_ir(body, state, top_node(body, 3), 2);
  sub.presses.resize(2);
  sub.presses[1] = {true, Eigen::Vector3d(0.01, 0.02, 0.03)};
  sub.remote_users = {1};
  sub.remote_radii = {0.002};
  ir.body = sub;
  std::string bytes;
  ASSERT_TRUE(wire::to_wire(ir).SerializeToString(&bytes));
  wire::IntermediateRepresentation parsed;
  ASSERT_TRUE(parsed.ParseFromString(bytes));
  const auto back = std::get<MassSpringIr>(wire::from_wire(parsed).body);
  EXPECT_EQ(back.node_ids, sub.node_ids);
  EXPECT_EQ(back.positions, sub.positions);
  EXPECT_EQ(back.velocities, sub.velocities);
  EXPECT_EQ(back.mass, sub.mass);
  EXPECT_EQ(back.held, sub.held);
  ASSERT_EQ(back.springs.size(), sub.springs.size());
  EXPECT_EQ(back.springs.back().stiffness, sub.springs.back().stiffness);
  EXPECT_EQ(back.triangles, sub.triangles);
  EXPECT_EQ(back.presses[1].previous, sub.presses[1].previous);
  EXPECT_EQ(back.parameters.time_step, sub.parameters.time_step);

  parsed.mutable_mass_spring()->set_spring_nodes(5, 100000);
  try {
    wire::from_wire(parsed);
    FAIL() << "a spring naming a node out of range was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("spring 2 names node 100000"), std::string::npos) << e.what();
  }
}

// A tool of radius 2 mm over the top of the middle section, pressing down by `depth` [m]
// over the first 0.1 s.
Eigen::Vector3d pressing_tool(const MassSpringModel& body, double t, double depth) {
  const Eigen::Vector3d top = body.network.rest_positions.col(top_node(body, body.section_count / 2));
  return top + Eigen::Vector3d(0, 0, 0.002 - depth * std::min(t / 0.1, 1.0));
}

// The server steps at 1 kHz; the client takes each new IR through the wire and evaluates
// it every 1 ms with the same tool positions; the server's P0 evaluation runs beside it.
struct Lockstep {
  explicit Lockstep(const MassSpringModel& body) : simulation(body, 0, {ToolSpec{"A", ToolShape::sphere, 0.002}}, 3.3) {}
  MassSpringSimulation simulation;
  std::unique_ptr<PreparedIR> client;
  EvaluationState client_state;
  std::uint64_t epoch = 0;
  int irs = 0;
  void take_ir() {
    const auto ir = simulation.ir(0);
    if (!ir || ir->ir.epoch == epoch) return;
    epoch = ir->ir.epoch;
    ++irs;
    client = std::make_unique<PreparedIR>(prepare_ir(wire::from_wire(wire::to_wire(ir->ir))));
    client_state = make_evaluation_state(*client);
  }
};

TEST(MassSpringSimulation, ClientForceThroughTheWireIsTheServersP0ForceBitForBit) {
  Lockstep run(noodle());
  const double dt = 1.0 / 1024;  // exact in binary: the server's periods t - t_previous are exactly dt
  int compared = 0, in_contact = 0;
  double largest = 0;
  for (int tick = 0; tick < 400; ++tick) {
    const double t = tick * dt;
    const Eigen::Vector3d tool = pressing_tool(noodle(), t, 0.002);
    run.simulation.set_tool(0, tool);
    run.simulation.step(t);
    run.take_ir();
    if (!run.client) continue;
    const ForceSample server = run.simulation.force(0, dt);
    const ForceSample client = evaluate_force(*run.client, run.client_state, tool, {}, dt);
    ASSERT_TRUE(same_bits(server.force, client.force)) << "tick " << tick;
    ASSERT_EQ(server.flags, client.flags);
    ++compared;
    in_contact += (client.flags & kInContact) != 0;
    largest = std::max(largest, client.force.norm());
  }
  EXPECT_GT(compared, 350);
  EXPECT_GT(in_contact, 0);
  EXPECT_GT(largest, 0.01) << "the tool pressed";
  // 100 IRs per second while the tool is near (scenes/thin/noodle.yaml's ir.rate_hz): one
  // on the first step at or after 10 ms since the previous.
  EXPECT_NEAR(run.irs, 400.0 / std::ceil(0.01 / dt), 1);
}

// The client's force from the IR against the server's whole network run at the haptic
// rate with the same tool. On the tick an IR arrives the client takes the step the server
// would take next: identical when the IR is the whole network. Between IRs the client
// runs a tick ahead of the server (its tool one tick behind), and a sub-network's rim is
// held at the server's velocity: within 10 % of the largest force for 4 sections a side.
TEST(MassSpringSimulation, SubNetworkForceFollowsTheWholeNetwork) {
  for (const int sections : {1000, 4}) {
    MassSpringModel body = noodle();
    body.spec.ir.sections = sections;
    Lockstep run(body);
    MassSpringState whole = make_state(body.network);
    std::array<ToolPress, 1> press;
    std::array<NetworkToolReaction, 1> reaction;
    const double dt = 1.0 / 1024;
    double largest = 0, worst = 0;
    for (int tick = 0; tick < 400; ++tick) {
      const double t = tick * dt;
      const Eigen::Vector3d tool = pressing_tool(body, t, 0.002);
      // The server's own network, advanced before the IR is cut, as the reference.
      run.simulation.set_tool(0, tool);
      run.simulation.step(t);
      const int irs_before = run.irs;
      run.take_ir();
      const bool fresh = run.irs != irs_before;
      const std::array<ToolOnNetwork, 1> tools{ToolOnNetwork{tool, 0.002}};
      if (tick > 0) advance_with_tools(body.network, whole, tools, press, reaction, dt);
      if (!run.client) continue;
      const ForceSample client = evaluate_force(*run.client, run.client_state, tool, {}, dt);
      // The reference one tick on: the IR was cut after the server's step at t, the
      // client's evaluation advances from there to t + dt.
      MassSpringState ahead = whole;
      std::array<ToolPress, 1> ahead_press = press;
      std::array<NetworkToolReaction, 1> ahead_reaction;
      advance_with_tools(body.network, ahead, tools, ahead_press, ahead_reaction, dt);
      if (sections == 1000 && fresh) {
        ASSERT_TRUE(same_bits(client.force, ahead_reaction[0].force)) << "tick " << tick;
      }
      largest = std::max(largest, ahead_reaction[0].force.norm());
      worst = std::max(worst, (client.force - ahead_reaction[0].force).norm());
    }
    EXPECT_GT(largest, 1e-4) << "the tool pressed";
    EXPECT_LT(worst, 0.1 * largest) << sections << " sections";
    std::printf("sections %d: largest force %.4g N, largest difference %.3g N\n", sections, largest, worst);
  }
}

// Two noodles 5 cm apart; a user goes to the one its tool is nearest.
TEST(SceneSimulation, AssignsEachUserToTheNearestBodyWithRisingEpochs) {
  const std::string yaml = R"(name: two_noodles
units: mm
objects:
  - name: left
    model: mass_spring
    tube: {centre_line: [[0, 0, 4.6194], [40, 0, 4.6194]], radius: 5, sections: 12}
    material: {youngs_modulus: 737.4, density: 9049}
    plane: {point: [0, 0, 0], normal: [0, 0, 1], static_friction: 0.5, dynamic_friction: 0.2}
  - name: right
    model: mass_spring
    tube: {centre_line: [[0, 50, 4.6194], [40, 50, 4.6194]], radius: 5, sections: 12}
    material: {youngs_modulus: 737.4, density: 9049}
    plane: {point: [0, 0, 0], normal: [0, 0, 1], static_friction: 0.5, dynamic_friction: 0.2}
tools:
  - {name: A, shape: sphere, radius: 2}
haptic: {rate_hz: 1000, force_limit: 3.3}
)";
  const Model model = build_model(parse_scene(yaml, "two_noodles.yaml"));
  const SceneCompliance compliance = prepare_scene_compliance(model, false, std::nullopt);
  SceneSimulation simulation(model, compliance.per_body, model.scene.tools, SimulationOptions{});
  double t = 0;
  std::uint64_t epoch = 0;
  const auto run_at = [&](const Eigen::Vector3d& tool, double seconds) {
    for (int i = 0; i < static_cast<int>(seconds / 0.001); ++i, t += 0.001) {
      simulation.set_tool(0, tool);
      simulation.step(t);
      if (simulation.ir_changed(0)) {
        EXPECT_GT(simulation.ir(0)->ir.epoch, epoch);
        epoch = simulation.ir(0)->ir.epoch;
        EXPECT_EQ(simulation.ir(0)->ir.object, simulation.body_of(0));
      }
    }
  };
  run_at(Eigen::Vector3d(0.02, 0.05, 0.03), 0.05);  // far above both
  EXPECT_EQ(simulation.ir(0), nullptr);
  run_at(Eigen::Vector3d(0.02, 0.05, 0.0125), 0.05);  // just above the right one (its top at 9.2 mm)
  EXPECT_EQ(simulation.body_of(0), 1);
  ASSERT_NE(simulation.ir(0), nullptr);
  run_at(Eigen::Vector3d(0.02, 0.05, 0.008), 0.05);  // pressing it
  EXPECT_EQ(simulation.body_of(0), 1);
  run_at(Eigen::Vector3d(0.02, 0.0, 0.0125), 0.05);  // lifted, over the left one
  EXPECT_EQ(simulation.body_of(0), 0);
  EXPECT_EQ(simulation.ir(0)->ir.object, 0);
}

}  // namespace
}  // namespace cohaptic
