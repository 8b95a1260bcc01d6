// The mass-spring body on the server and through the IR: the sub-network an IR carries
// (its sections, rim and springs against the body's), the client's force against the
// server's whole network (bit for bit when the IR carries the whole network, within a
// bound for a sub-network), the client's force through the wire against the server's P0
// evaluation in lockstep (bit for bit), the IR rate, the scene's noodle dropped and slid on
// its plane against a rigid body's closed forms, and SceneSimulation's assignment of users
// to the nearest of two bodies with epochs that keep rising.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <span>
#include <vector>

#include "common/ir/build_mass_spring_ir.h"
#include "common/mass_spring/integrate_network.h"
#include "common/mass_spring/internal_forces.h"
#include "common/mass_spring/plane_friction.h"
#include "common/mass_spring/stable_time_step.h"
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

bool same_bits(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::memcmp(a.data(), b.data(), sizeof(double) * 3) == 0;
}

const Model& noodle_model() {
  static const Model model =
      build_model(load_scene(testing::source_path("scenes/thin/noodle.yaml")));
  return model;
}

const MassSpringModel& noodle() { return std::get<MassSpringModel>(noodle_model().bodies.front()); }

// A node on the top of the tube in section `section`.
int top_node(const MassSpringModel& body, int section) {
  int best = kSectionNodes * section + 1;
  for (int k = 1; k <= kRingNodes; ++k)
    if (body.network.rest_positions(2, kSectionNodes * section + k) >
        body.network.rest_positions(2, best))
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
    const int section =
        body.section_of_node[static_cast<std::size_t>(ir.node_ids[static_cast<std::size_t>(i)])];
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
    const int a = body.section_of_node[static_cast<std::size_t>(s.a)],
              b = body.section_of_node[static_cast<std::size_t>(s.b)];
    inside += std::abs(a - middle) <= 5 && std::abs(b - middle) <= 5;
  }
  ASSERT_EQ(ir.springs.size(), inside);
  for (const Spring& s : ir.springs) {
    const Spring* original = body_springs.at(
        {ir.node_ids[static_cast<std::size_t>(s.a)], ir.node_ids[static_cast<std::size_t>(s.b)]});
    EXPECT_EQ(s.stiffness, original->stiffness);
    EXPECT_EQ(s.rest_length, original->rest_length);
    EXPECT_EQ(s.damping, original->damping);
  }

  // At an end: no rim beyond it. Wider than the body: the whole network, nothing held.
  const MassSpringIr end = build_mass_spring_ir(body, state, top_node(body, 0), 4);
  EXPECT_EQ(end.node_count(), (4 + 1 + 1) * kSectionNodes);
  const MassSpringIr whole =
      build_mass_spring_ir(body, state, top_node(body, middle), body.section_count);
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
    EXPECT_NE(std::string(e.what()).find("spring 2 names node 100000"), std::string::npos)
        << e.what();
  }
}

// A tool of radius 2 mm over the top of the middle section, pressing down by `depth` [m]
// over the first 0.1 s.
Eigen::Vector3d pressing_tool(const MassSpringModel& body, double t, double depth) {
  const Eigen::Vector3d top =
      body.network.rest_positions.col(top_node(body, body.section_count / 2));
  return top + Eigen::Vector3d(0, 0, 0.002 - depth * std::min(t / 0.1, 1.0));
}

// The server steps at 1 kHz; the client takes each new IR through the wire and evaluates
// it every 1 ms with the same tool positions; the server's P0 evaluation runs beside it.
struct Lockstep {
  // The server advances by the test's tick, 1/1024 s: exact in binary, so its step times'
  // differences are exactly one tick.
  explicit Lockstep(const MassSpringModel& body)
      : simulation(body, 0, {ToolSpec{"A", ToolShape::sphere, 0.002, {}}}, 3.3, 1.0 / 1024) {}
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
  const double dt =
      1.0 / 1024;  // exact in binary: the server's periods t - t_previous are exactly dt
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
    std::printf("sections %d: largest force %.4g N, largest difference %.3g N\n", sections, largest,
                worst);
  }
}

// The noodle as its scene file makes it (scenes/thin/noodle.yaml, with the paper's nodal
// damping beta = 0.007 N s/m) dropped onto its plane and slid along it, against the closed
// forms of a rigid body of mass M under gravity, Coulomb friction mu_d M g and the damping
// -beta N v of its N nodes (rate c = beta N / M), integrated by semi-implicit Euler at the
// body's step h: v_n = v_inf (1 - r^n) with r = 1 - c h, so the fall after n steps is
// h v_inf (n - r (1 - r^n) / (1 - r)) with v_inf = g / c; sliding from v0, the speed falls by
// h (mu_d g + c v) a step until it stops.
double rigid_fall(double g, double c, double h, int steps) {
  const double r = 1 - c * h, v_inf = g / c;
  return h * v_inf * (steps - r * (1 - std::pow(r, steps)) / (1 - r));
}

double rigid_slide(double v0, double friction_deceleration, double c, double h) {
  double v = v0, distance = 0;
  while (true) {
    v -= h * (friction_deceleration + c * v);
    if (v <= 0) return distance;
    distance += h * v;
  }
}

struct DropAndSlide {
  double fall = 0, expected_fall = 0, lowest = 0, landed_lowest = 0, landed_speed = 0,
         rest_offset = 0, slide = 0, expected_slide = 0, speed_after = 0;
};

// Dropped from 20 mm for 50 ms, then left 1 s to land; set on the plane at rest, pushed
// along it at v0 = 0.2 m/s and left 1 s.
DropAndSlide drop_and_slide(const MassSpringNetwork& network) {
  const double h = network.parameters.time_step, g = -network.parameters.gravity.z();
  const double total_mass = network.mass.sum(),
               c = network.parameters.node_damping * network.node_count() / total_mass;
  const auto centre_of_mass = [&](const MassSpringState& s) -> Eigen::Vector3d {
    return s.positions * network.mass / total_mass;
  };
  const auto run = [&](MassSpringState& s, double seconds) {
    for (int i = 0; i < static_cast<int>(std::round(seconds / h)); ++i)
      step_network(network, s, {}, {}, h);
  };
  DropAndSlide result;
  MassSpringState resting = make_state(network);
  run(resting, 0.5);
  MassSpringState dropped = make_state(network);
  dropped.positions.row(2).array() += 0.02;
  const double start = centre_of_mass(dropped).z();
  const int falling = static_cast<int>(std::round(0.05 / h));
  for (int i = 0; i < falling; ++i) step_network(network, dropped, {}, {}, h);
  result.fall = start - centre_of_mass(dropped).z();
  result.expected_fall = rigid_fall(g, c, h, falling);
  result.lowest = 1;
  for (int i = 0; i < static_cast<int>(1.0 / h); ++i) {
    step_network(network, dropped, {}, {}, h);
    result.lowest = std::min(result.lowest, dropped.positions.row(2).minCoeff());
  }
  result.landed_lowest = dropped.positions.row(2).minCoeff();
  result.landed_speed = dropped.velocities.cwiseAbs().maxCoeff();
  result.rest_offset = centre_of_mass(dropped).z() - centre_of_mass(resting).z();

  const double v0 = 0.2;
  MassSpringState sliding = resting;
  sliding.velocities.setZero();
  sliding.velocities.row(0).setConstant(v0);
  const double x0 = centre_of_mass(sliding).x();
  run(sliding, 1.0);
  result.slide = centre_of_mass(sliding).x() - x0;
  result.expected_slide = rigid_slide(v0, network.parameters.plane->dynamic_friction * g, c, h);
  result.speed_after = sliding.velocities.cwiseAbs().maxCoeff();
  std::printf(
      "fell %.4g mm in 50 ms (closed form %.4g); slid from %.2f m/s %.4g mm (closed form %.4g; "
      "without damping %.4g)\n",
      result.fall * 1e3, result.expected_fall * 1e3, v0, result.slide * 1e3,
      result.expected_slide * 1e3,
      v0 * v0 / (2 * network.parameters.plane->dynamic_friction * g) * 1e3);
  return result;
}

// The scene's noodle falls as the rigid body does (its springs carry no load in free fall),
// lands without a node below the plane and comes to rest on it (0.13 mm lower than the noodle
// set down gently: the soft tube spreads on landing, and friction keeps its footprint). Sliding,
// the soft noodle (E = 737 Pa: it sags to half its height under its own weight) goes 7 % further
// than a rigid body, its upper part rolling on after its base stops; with its springs 100 times
// stiffer (the step shortened to stay stable) it slides as the rigid body does.
TEST(MassSpringSimulation, NoodleSceneDroppedAndSlidFollowsTheRigidClosedForms) {
  const MassSpringNetwork& network = noodle().network;
  ASSERT_GT(network.parameters.node_damping, 0);
  const DropAndSlide soft = drop_and_slide(network);
  EXPECT_NEAR(soft.fall, soft.expected_fall, 0.02 * soft.expected_fall);
  EXPECT_GE(soft.lowest, 0.0) << "a node went below the plane";
  EXPECT_LT(soft.landed_lowest, kPlaneTouchTolerance) << "it landed";
  EXPECT_LT(soft.landed_speed, 1e-3) << "and came to rest";
  EXPECT_LT(soft.speed_after, 1e-3);

  MassSpringNetwork stiff = network;
  for (Spring& s : stiff.springs) {
    s.stiffness *= 100;
    s.damping *= 100;
  }
  stiff.parameters.time_step = 0.8 * critical_time_step(stiff);
  const DropAndSlide rigid = drop_and_slide(stiff);
  EXPECT_NEAR(rigid.fall, rigid.expected_fall, 0.01 * rigid.expected_fall);
  EXPECT_GE(rigid.lowest, 0.0) << "a node went below the plane";
  EXPECT_LT(std::abs(rigid.rest_offset), 2e-5) << "it rests where it rested";
  EXPECT_LT(rigid.landed_speed, 1e-3);
  EXPECT_NEAR(rigid.slide, rigid.expected_slide, 0.03 * rigid.expected_slide);
  EXPECT_LT(rigid.speed_after, 1e-3);
}

// A scripted tool driven through the server's simulation of `body` (the scene's tools, one
// user): from `start` at `velocity` [m/s] for `seconds`, 1 ms periods. The whole network's
// reaction on the tool each period.
std::vector<Eigen::Vector3d> move_tool(MassSpringSimulation& simulation, double& time,
                                       const Eigen::Vector3d& start,
                                       const Eigen::Vector3d& velocity, double seconds) {
  std::vector<Eigen::Vector3d> forces;
  const int periods = static_cast<int>(std::round(seconds / 1e-3));
  for (int i = 1; i <= periods; ++i) {
    simulation.set_tool(0, start + velocity * (i * 1e-3));
    time += 1e-3;
    simulation.step(time);
    forces.push_back(simulation.reaction(0).force);
  }
  return forces;
}

Eigen::Vector3d mean_of(std::span<const Eigen::Vector3d> forces) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& f : forces) sum += f;
  return sum / static_cast<double>(forces.size());
}

// A tool pushing a resting tube along its plane at constant speed v, against the steady
// sliding of a rigid body: every node moves at v, so the plane's dynamic friction is
// mu_d (M g - L) (L the tool's lift on the body, the weight of the nodes it holds and the
// vertical part of its push) and the nodal damping adds beta N v; the tool must supply
// their sum. The scene's noodle with its springs 100 times stiffer (E = 737 Pa would let
// the tube's own friction, 0.11 N, compress it by more than its length: E A = 0.058 N; the
// tool sinks into it), the scene's 2 mm sphere against the left end cap, 20 mm/s, mean over
// the last second of 1.5 s; springs damped as the scene has them (alpha = 1e-6 s) and at
// alpha = 1e-4 s.
TEST(MassSpringSimulation, ToolPushingTheTubeAlongThePlaneFeelsItsSlidingFriction) {
  for (const double alpha : {1e-6, 1e-4}) {
    SCOPED_TRACE("alpha " + std::to_string(alpha));
    MassSpringModel stiff = noodle();
    for (Spring& s : stiff.network.springs) {
      s.stiffness *= 100;
      s.damping = alpha * s.stiffness;
    }
    stiff.network.parameters.time_step = 0.8 * critical_time_step(stiff.network);
    MassSpringSimulation simulation(stiff, 0, noodle_model().scene.tools, 3.3, 1e-3);
    double time = 0;
    simulation.step(time);
    const double radius = noodle_model().scene.tools[0].radius, speed = 0.02;
    const MassSpringNetwork& network = stiff.network;
    const double mass = network.mass.sum(), g = -network.parameters.gravity.z();
    const double mu = network.parameters.plane->dynamic_friction,
                 beta = network.parameters.node_damping;
    const double axis = network.rest_positions(2, 0);  // section 0's centre node, on the end cap
    const Eigen::Vector3d start(-radius - 0.001, 0, axis), velocity(speed, 0, 0);
    const auto centre_x = [&] { return (simulation.state().positions * network.mass).x() / mass; };
    const std::vector<Eigen::Vector3d> starting = move_tool(simulation, time, start, velocity, 0.5);
    const double from = centre_x();
    const std::vector<Eigen::Vector3d> forces =
        move_tool(simulation, time, start + 0.5 * velocity, velocity, 1.0);
    const double centre_speed = centre_x() - from;  // over 1 s
    for (const Eigen::Vector3d& f : starting) ASSERT_TRUE(f.allFinite());
    const Eigen::Vector3d mean = mean_of(forces);
    const double lift = -mean.z();
    const double expected = mu * (mass * g - lift) + beta * network.node_count() * speed;
    std::printf(
        "push along (alpha %g s): mean force on the tool %.4f %.4f %.4f N; mu_d (M g - L) + beta N "
        "v = %.4f N "
        "(mu_d M g = %.4f, beta N v = %.4f, L = %.4f N); tube at %.2f mm/s\n",
        alpha, mean.x(), mean.y(), mean.z(), expected, mu * mass * g,
        beta * network.node_count() * speed, lift, 1e3 * centre_speed);
    EXPECT_NEAR(-mean.x(), expected, 0.05 * expected);
    EXPECT_NEAR(centre_speed, speed, 0.01 * speed) << "the tube slides with the tool";
    EXPECT_LT(std::abs(mean.y()), 0.05 * expected);
    for (const Eigen::Vector3d& f : forces) ASSERT_TRUE(f.allFinite());
  }
}

// The scene's noodle, springs 100 times stiffer but damped as the scene has them (alpha =
// 1e-6 s), dragged along its plane at 20 mm/s by its first section, held and moved at that
// speed. The pull on the held section (minus the springs' forces on it) over the second after
// a 0.5 s start, against a rigid body's steady sliding: mu_d (m g - L) + beta N v over the
// free nodes (L the pull's lift). A sliding node that kinetic friction cannot stop within a
// step keeps sliding (plane_friction.h); stopping it with static friction made this barely
// damped tube stick and slip, and the pull was 0.05 N.
TEST(MassSpringSimulation, TubeDraggedByItsEndFeelsItsSlidingFriction) {
  MassSpringNetwork network = noodle().network;
  for (Spring& s : network.springs) {
    s.stiffness *= 100;
    s.damping *= 100;
  }
  network.parameters.time_step = 0.8 * critical_time_step(network);
  const double h = network.parameters.time_step, speed = 0.02;
  const MassSpringParameters& p = network.parameters;
  MassSpringState state = make_state(network);
  for (int i = 0; i < static_cast<int>(0.3 / h); ++i) step_network(network, state, {}, {}, h);
  for (int n = 0; n < kSectionNodes; ++n) {
    network.held[static_cast<std::size_t>(n)] = 1;
    state.velocities.col(n) = Eigen::Vector3d(speed, 0, 0);
  }
  double free_mass = 0;
  for (int n = kSectionNodes; n < network.node_count(); ++n) free_mass += network.mass[n];
  const int start = static_cast<int>(0.5 / h), steps = static_cast<int>(1.5 / h);
  Eigen::Matrix3Xd forces(3, network.node_count());
  Eigen::Vector3d pull = Eigen::Vector3d::Zero();
  for (int i = 0; i < steps; ++i) {
    step_network(network, state, {}, {}, h);
    if (i < start) continue;
    internal_forces(network, state.positions, state.velocities, forces);
    for (int n = 0; n < kSectionNodes; ++n)  // the springs' pull on the held node, reversed
      pull -=
          forces.col(n) - network.mass[n] * p.gravity + p.node_damping * state.velocities.col(n);
  }
  pull /= steps - start;
  const double free_nodes = network.node_count() - kSectionNodes;
  const double expected = p.plane->dynamic_friction * (free_mass * -p.gravity.z() - pull.z()) +
                          p.node_damping * free_nodes * speed;
  std::printf("dragged by its end: pull %.4f %.4f %.4f N, mu_d (m g - L) + beta N v = %.4f N\n",
              pull.x(), pull.y(), pull.z(), expected);
  EXPECT_NEAR(pull.x(), expected, 0.05 * expected);
  EXPECT_LT(std::abs(pull.y()), 0.05 * expected);
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
  run_at(Eigen::Vector3d(0.02, 0.05, 0.0125),
         0.05);  // just above the right one (its top at 9.2 mm)
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
