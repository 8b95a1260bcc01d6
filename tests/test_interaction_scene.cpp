// The scene's `interactions:` list and SceneSimulation running it: the paired-boxes scene
// (scenes/objects/paired_boxes.yaml), a mass-spring object A lying on the linear elastic box
// B under gravity with no plane under it. Checked against independent answers: A's weight
// (its masses times g) is what B's reaction must carry once A is at rest, and A's weight
// plus the tool's push once a tool presses A; A dropped onto B never gains energy; the
// client feels B through A as the server does; without the interaction A falls freely.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>

#include "common/mass_spring/internal_forces.h"
#include "common/model/model.h"
#include "common/model/scene_compliance.h"
#include "common/scene/load_scene.h"
#include "common/sim/scene_simulation.h"
#include "common/util/error.h"
#include "proto/wire/ir_convert.h"
#include "support/test_meshes.h"

namespace cohaptic {
namespace {

std::string paired_boxes_text() {
  std::ifstream in(testing::source_path("scenes/objects/paired_boxes.yaml"));
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The scene's text with its interactions replaced by `interactions` (YAML, "" for none).
std::string with_interactions(const std::string& interactions) {
  std::string text = paired_boxes_text();
  const std::string key = "interactions:\n  - {front: A, behind: B}\n";
  const auto at = text.find(key);
  EXPECT_NE(at, std::string::npos);
  return text.replace(at, key.size(), interactions);
}

void expect_scene_error(const std::string& interactions, const std::string& expected) {
  try {
    parse_scene(with_interactions(interactions), "paired.yaml");
    ADD_FAILURE() << "no error for " << interactions;
  } catch (const SceneError& error) {
    EXPECT_NE(std::string(error.what()).find(expected), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("paired.yaml:"), std::string::npos) << error.what();
  }
}

TEST(InteractionScene, ParsesThePairsAndRejectsWhatCannotPress) {
  const Scene scene = load_scene(testing::source_path("scenes/objects/paired_boxes.yaml"));
  ASSERT_EQ(scene.interactions.size(), 1u);
  EXPECT_EQ(scene.interactions[0].front, "A");
  EXPECT_EQ(scene.interactions[0].behind, "B");
  EXPECT_TRUE(parse_scene(with_interactions(""), "paired.yaml").interactions.empty());
  expect_scene_error("interactions:\n  - {front: A, behind: C}\n",
                     "no object named 'C' (the scene's objects: A, B)");
  expect_scene_error("interactions:\n  - {front: A, behind: A}\n",
                     "an object other than the front one");
  expect_scene_error("interactions:\n  - {front: B, behind: A}\n",
                     "object 'A' is not linear elastic");
  expect_scene_error("interactions:\n  - {front: A, behind: B}\n  - {front: A, behind: B}\n",
                     "object 'A' is the front of an earlier interaction already");
  expect_scene_error("interactions:\n  - {front: A, behind: B, friction: 1}\n", "friction");
  expect_scene_error("interactions:\n  - {front: A}\n", "behind");
}

struct PairedBoxes {
  Model model;
  SceneCompliance compliance;
  SceneSimulation simulation;
  double time = 0;
  explicit PairedBoxes(const std::string& text)
      : model(build_model(
            parse_scene(text, testing::source_path("scenes/objects/paired_boxes.yaml")))),
        compliance(prepare_scene_compliance(model, true, std::nullopt)),
        simulation(model, compliance.per_body, model.scene.tools, SimulationOptions{}) {}
  const MassSpringSimulation& front() const {
    return std::get<MassSpringSimulation>(simulation.body(0));
  }
  void run(double seconds) {
    for (int i = 0; i < static_cast<int>(std::lround(seconds / 0.001)); ++i, time += 0.001)
      simulation.step(time);
  }
  double weight() const { return front().body().network.mass.sum() * 9.81; }
  // The backing's force on A at its current positions, summed over A's nodes [N].
  Eigen::Vector3d backing_force() const {
    const MassSpringNetwork& network = front().body().network;
    Eigen::Matrix3Xd forces = Eigen::Matrix3Xd::Zero(3, network.node_count());
    NodeBackingSolve solve = front().state().backing;
    add_node_backing_forces(front().backing(), solve, front().state().positions,
                            front().state().velocities, forces);
    return forces.rowwise().sum();
  }
  // A's energy: kinetic, gravity, springs and B's elastic energy under the backing [J].
  double energy() const {
    const MassSpringNetwork& network = front().body().network;
    const MassSpringState& state = front().state();
    NodeBackingSolve solve = state.backing;
    Eigen::Matrix3Xd forces = Eigen::Matrix3Xd::Zero(3, network.node_count());
    add_node_backing_forces(front().backing(), solve, state.positions,
                            Eigen::Matrix3Xd::Zero(3, network.node_count()), forces);
    return kinetic_energy(network, state.velocities) + potential_energy(network, state.positions) +
           backing_energy(front().backing(), solve.pushes);
  }
  double lowest() const { return front().state().positions.row(2).minCoeff(); }
};

TEST(InteractionScene, BehindBoxCarriesTheFrontObjectsWeightAndATool) {
  PairedBoxes boxes(paired_boxes_text());
  boxes.run(2.0);
  // Over a window in which A's momentum hardly changes, B's reaction averages the weight it
  // carries (averaged over the window: a settled A still trembles by micrometres between steps).
  const auto carried_over = [&](double seconds, const std::optional<Eigen::Vector3d>& tool) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    double pushed = 0;
    const int steps = static_cast<int>(std::lround(seconds / 0.001));
    for (int i = 0; i < steps; ++i, boxes.time += 0.001) {
      if (tool) boxes.simulation.set_tool(0, *tool);
      boxes.simulation.step(boxes.time);
      sum += boxes.backing_force();
      pushed += boxes.front()
                    .reaction(0)
                    .force.z();  // A pushes the tool up as hard as the tool pushes A down
    }
    return std::pair(Eigen::Vector3d(sum / steps), pushed / steps);
  };
  const auto [carried, no_push] = carried_over(0.5, std::nullopt);
  const MassSpringState& state = boxes.front().state();
  ASSERT_TRUE(state.positions.allFinite());
  EXPECT_LT(state.velocities.cwiseAbs().maxCoeff(), 0.01);  // settled [m/s]
  EXPECT_NEAR(carried.z(), boxes.weight(), 0.02 * boxes.weight());
  EXPECT_NEAR(carried.head<2>().norm(), 0, 0.02 * boxes.weight());
  EXPECT_EQ(no_push, 0);
  EXPECT_LT(boxes.lowest(), 0);      // A sank into B's rest surface as B gave way ...
  EXPECT_GT(boxes.lowest(), -1e-3);  // ... by less than a millimetre
  EXPECT_FALSE(boxes.front().backing().empty());
  EXPECT_EQ(boxes.front().state().backing.failures, 0u);

  // A tool pressing A's top 3 mm down: B then carries the weight and the tool's push.
  const double top = state.positions.row(2).maxCoeff();
  const Eigen::Vector3d tool(0, 0, top + 0.002 - 0.003);
  carried_over(1.5, tool);
  const auto [pressed, push] = carried_over(0.5, tool);
  ASSERT_TRUE(boxes.front().state().positions.allFinite());
  EXPECT_GT(push, 0.05);
  EXPECT_NEAR(pressed.z(), boxes.weight() + push, 0.02 * (boxes.weight() + push));
}

// A dropped onto B (0.2 mm above its top face) never gains energy: the backing is B's
// elastic energy, the dampers (A's and the backing's) only take energy out, so the total
// (kinetic, gravity, springs, B's energy under the pushes) only falls, step after step, up
// to a small allowance for the integrator's O(h) wobble and for the backing's rebuild each
// step (new targets as A slides). A backing that pumped energy let A bounce off B and fall
// through it.
TEST(InteractionScene, TheFrontObjectDroppedOnTheBoxNeverGainsEnergyAndSettles) {
  PairedBoxes boxes(paired_boxes_text());
  const double start = boxes.energy();
  double lowest = start, largest_rise = 0, stored = 0;
  for (int i = 0; i < 2000; ++i, boxes.time += 0.001) {
    boxes.simulation.step(boxes.time);
    const double energy = boxes.energy();
    largest_rise = std::max(largest_rise, energy - lowest);  // above the lowest so far
    lowest = std::min(lowest, energy);
    stored = std::max(
        stored, backing_energy(boxes.front().backing(), boxes.front().state().backing.pushes));
  }
  const double drop = boxes.weight() * 0.2e-3;  // A's fall onto B's rest surface [J]
  EXPECT_GT(stored, 0);
  EXPECT_LT(largest_rise, 0.01 * drop);                                     // never gained energy
  EXPECT_LT(boxes.front().state().velocities.cwiseAbs().maxCoeff(), 0.01);  // settled [m/s]
  EXPECT_GT(boxes.lowest(), -1e-3);
  EXPECT_EQ(boxes.front().state().backing.failures, 0u);
  std::cout << "drop " << drop << " J, lost " << start - lowest << " J, largest rise "
            << largest_rise << " J, B stored at most " << stored << " J\n";
}

// The client feels B through A: the IR of a user pressing A carries B's backing on the
// sub-network, and the client's evaluation of the IR that came through the wire gives the
// server's P0 force tick for tick (1e-9 N); without the backing it would not.
TEST(InteractionScene, ClientFeelsTheBehindBoxThroughTheWireAsTheServerDoes) {
  PairedBoxes boxes(paired_boxes_text());
  boxes.run(1.0);
  const double top = boxes.front().state().positions.row(2).maxCoeff();
  const Eigen::Vector3d start(0, 0.004, top + 0.002 + 0.001);
  std::optional<PreparedIR> client, unbacked;
  EvaluationState client_state, unbacked_state;
  double previous = boxes.time, largest_difference = 0, largest_force = 0, backing_effect = 0;
  int irs = 0, backed_irs = 0;
  for (int i = 1; i <= 600; ++i) {
    const double t = boxes.time + 0.001 * i;
    const Eigen::Vector3d tool = start - Eigen::Vector3d(0, 0, 0.008 * std::min(1.0, i / 300.0));
    boxes.simulation.set_tool(0, tool);
    boxes.simulation.step(t);
    const double dt = t - previous;
    previous = t;
    if (boxes.simulation.ir_changed(0)) {
      IntermediateRepresentation received =
          wire::from_wire(wire::to_wire(boxes.simulation.ir(0)->ir));
      const auto& network = std::get<MassSpringIr>(received.body);
      ++irs;
      if (!network.backing.empty()) ++backed_irs;
      IntermediateRepresentation stripped = received;
      std::get<MassSpringIr>(stripped.body).backing = {};
      client.emplace(prepare_ir(std::move(received)));
      client_state = make_evaluation_state(*client);
      unbacked.emplace(prepare_ir(std::move(stripped)));
      unbacked_state = make_evaluation_state(*unbacked);
    }
    const ForceSample server = boxes.simulation.force(0);
    if (!client) continue;
    const ForceSample felt = evaluate_force(*client, client_state, tool, {}, dt);
    const ForceSample without = evaluate_force(*unbacked, unbacked_state, tool, {}, dt);
    ASSERT_TRUE(felt.force.allFinite());
    largest_difference = std::max(largest_difference, (felt.force - server.force).norm());
    largest_force = std::max(largest_force, felt.force.norm());
    backing_effect = std::max(backing_effect, (felt.force - without.force).norm());
  }
  EXPECT_GT(irs, 10);
  EXPECT_EQ(backed_irs, irs);
  EXPECT_GT(largest_force, 0.05);
  EXPECT_LE(largest_difference, 1e-9);
  EXPECT_GT(backing_effect, 1e-3);  // the backing is felt, not carried for show
}

TEST(InteractionScene, WithoutTheInteractionTheFrontObjectFallsThroughTheBox) {
  PairedBoxes boxes(with_interactions(""));
  boxes.run(0.2);
  // Free fall for 0.2 s: 0.5 g t^2 = 196 mm, less what air-like node damping takes.
  EXPECT_LT(boxes.lowest(), -0.1);
}

}  // namespace
}  // namespace cohaptic
