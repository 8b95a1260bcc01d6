// FEM against FEM in a scene (common/sim/fem_pair_interaction.h): the paired
// boxes (support/paired_boxes.h, A E = 0.1 MPa in front of the paper's box B, both linear
// elastic) with `interactions: [{front: front, behind: behind}]`, run by SceneSimulation
// as the server runs it, a scripted point tool pressing A's front face towards B under the
// translation contact model. Against independent answers:
// - the server's force on the tool (P0: from the user's IR), A's displayed displacement and
//   B's equal one sparse solve of A and B together (support/joint_pair_solve.h: the tool's
//   triangle held at the tool's displacement, the contacts as Lagrange multipliers, its own
//   candidates from A's free state by brute force and its own active set), 1e-9, with A
//   touching B at rest and across a 0.5 mm gap (the IR's rest forces);
// - the client's force from that IR through the wire equals the server's (1e-9): B is in
//   the IR's M~ and rest forces, which travel whole (rows of A's own L would lose B);
// - the state solve with applied loads (the pushes) beside a tool and held nodes equals
//   CHOLMOD's full solve with the loads applied;
// - through the scene, free (no interaction) < on B < fixed (A's back face fixed);
// - the shipped scene's scripted surgeons feel B through A;
// - the loader and SceneSimulation refuse the pairs they cannot run, saying where.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <optional>
#include <string>
#include <unordered_map>

#include "common/condense/incremental_condensation.h"
#include "common/fem/static_solve.h"
#include "common/haptics/trajectory.h"
#include "common/ir/build_ir.h"
#include "common/ir/evaluate_force.h"
#include "common/model/scene_compliance.h"
#include "common/scene/load_scene.h"
#include "common/sim/ir_build_options.h"
#include "common/sim/scene_simulation.h"
#include "common/sim/state_solve.h"
#include "proto/wire/ir_convert.h"
#include "support/fem_pair_rig.h"
#include "support/joint_pair_solve.h"
#include "support/test_meshes.h"

namespace cohaptic {
namespace {

constexpr const char* kFemPairInteraction = "interactions:\n  - {front: front, behind: behind}\n";

testing::PairedBoxesOptions fem_pair_scene_options(double gap_mm) {
  testing::PairedBoxesOptions options;
  options.gap_mm = gap_mm;
  return options;
}

// The paired boxes with `extra` YAML appended (the interaction, a contact model).
Scene fem_pair_scene(double gap_mm, const std::string& extra) {
  return parse_scene(testing::paired_boxes_scene_yaml(fem_pair_scene_options(gap_mm)) + extra,
                     "fem-pair.yaml");
}

// `scene` with A's back face (x = -gap, towards B) fixed: the fixed condition.
Scene with_back_fixed(Scene scene, double gap_mm) {
  auto& front = std::get<ElasticObjectSpec>(scene.objects.front().body);
  FixedRegion back;
  back.nodes.kind = NodeSelector::Kind::plane;
  back.nodes.plane_point = Eigen::Vector3d(-gap_mm * 1e-3, 0, 0);
  back.nodes.plane_normal = Eigen::Vector3d::UnitX();
  back.nodes.where = "test: A's back face";
  front.fixed.push_back(back);
  return scene;
}

struct FemPairRun {
  Model model;
  SceneCompliance compliance;
  SceneSimulation simulation;
  explicit FemPairRun(Scene scene)
      : model(build_model(std::move(scene))),
        compliance(prepare_scene_compliance(model, true, std::nullopt)),
        simulation(model, compliance.per_body, model.scene.tools, [this] {
          SimulationOptions options;
          options.ir = ir_build_options(model.scene.haptic);
          options.ir.force_limit = 1000;  // compare forces, not the haptic limit
          return options;
        }()) {}
  // Two steps with the tool held still: the first forms the pushing set, the second keeps it.
  ForceSample press(const Eigen::Vector3d& tool) {
    for (double time : {0.0, 1e-3}) {
      simulation.set_tool(0, tool);
      simulation.step(time);
    }
    return simulation.force(0);
  }
  Simulation& fem(int body) { return std::get<Simulation>(simulation.body(body)); }
};

// The tool `depth` [m] into A's front face near its centre, a quarter and a half into a cell
// of the face: inside a triangle, away from its edges, whichever way the cell is split.
Eigen::Vector3d fem_pair_tool(double gap_mm, double depth) {
  return Eigen::Vector3d((-57.5 - gap_mm) * 1e-3 + depth, (15.95 + 2.25 * 98.9 / 5) * 1e-3,
                         (1.5 * 57.5 / 3) * 1e-3);
}

// The joint solve for a tool at `tool` under the translation model: the nearest triangle's
// nodes all moved by the tool's offset from the triangle's plane.
struct ExpectedPress {
  std::vector<PolygonCollision> candidates;  // A's back face at A's state alone, against B
  testing::JointPairSolution joint;
  Eigen::Vector3d force =
      Eigen::Vector3d::Zero();  // on the tool, as ForceSample gives it: -sum_i w_i f_i [N]
};

ExpectedPress expected_press(const testing::PairedBoxesRig& rig, const Eigen::Vector3d& tool) {
  const ElasticBody& a = rig.front;
  const Triangle& triangle =
      a.surface.triangles[static_cast<std::size_t>(nearest_touchable_triangle(a, tool))];
  const Eigen::Vector3d p0 = a.mesh.nodes.col(triangle[0]), p1 = a.mesh.nodes.col(triangle[1]),
                        p2 = a.mesh.nodes.col(triangle[2]);
  const Eigen::Vector3d cross = (p1 - p0).cross(p2 - p0);
  const Eigen::Vector3d normal = cross.normalized();
  const Eigen::Vector3d d = (tool - p0).dot(normal) * normal;
  const Eigen::Vector3d foot = tool - d;
  const Eigen::Vector3d weights((p1 - foot).cross(p2 - foot).dot(cross) / cross.squaredNorm(),
                                (p2 - foot).cross(p0 - foot).dot(cross) / cross.squaredNorm(),
                                (p0 - foot).cross(p1 - foot).dot(cross) / cross.squaredNorm());
  EXPECT_GT(weights.minCoeff(), 0.05);  // well inside the triangle
  std::vector<int> held;
  std::vector<double> values;
  for (int node : triangle)
    for (int axis = 0; axis < 3; ++axis)
      if (!a.dofs.is_fixed(node, axis)) {
        held.push_back(3 * node + axis);
        values.push_back(d[axis]);
      }
  const Eigen::VectorXd held_values =
      Eigen::Map<const Eigen::VectorXd>(values.data(), static_cast<Eigen::Index>(values.size()));
  const StaticSolution alone =
      ConstrainedStaticSolver(a.stiffness, a.dofs, held).solve(held_values);
  ExpectedPress expected;
  expected.candidates = testing::back_face_candidates(rig, alone.displacement);
  expected.joint = testing::joint_pair_solve(a, rig.behind, held, held_values, expected.candidates);
  for (int k = 0; k < 3; ++k)
    for (int axis = 0; axis < 3; ++axis)
      if (!a.dofs.is_fixed(triangle[static_cast<std::size_t>(k)], axis))
        expected.force[axis] -=
            weights[k] *
            expected.joint.front_reaction[3 * triangle[static_cast<std::size_t>(k)] + axis];
  return expected;
}

// The largest difference of `simulation`'s displacement at `body`'s surface from `expected`
// (3 per node), and the largest expected displacement there [m].
std::pair<double, double> surface_difference(Simulation& simulation, const ElasticBody& body,
                                             const Eigen::VectorXd& expected) {
  const Eigen::Matrix3Xd u = simulation.displacement_of(body.surface.nodes);
  double error = 0, largest = 0;
  for (std::size_t i = 0; i < body.surface.nodes.size(); ++i) {
    const Eigen::Vector3d reference = expected.segment<3>(3 * body.surface.nodes[i]);
    largest = std::max(largest, reference.norm());
    error = std::max(error, (u.col(static_cast<Eigen::Index>(i)) - reference).norm());
  }
  return {error, largest};
}

// The state solve with applied loads (what an FEM pair's pushes are to each body) beside a
// pressing tool and held nodes, against CHOLMOD's full solve with those dofs prescribed and
// the loads applied: the drawn displacement, the holding forces and the tool's force, 1e-9.
TEST(FemPairScene, AppliedLoadsBesideAToolAndHeldNodesAreTheFullSolves) {
  const testing::PairedBoxesRig rig(fem_pair_scene_options(0.0));
  const ElasticBody& a = rig.front;
  ComplianceColumns columns(a.free_factor, a.dofs, a.surface.nodes);
  IncrementalCondensation condensation(columns, a.dofs);
  std::vector<int> free_back;  // A's back-face nodes off its fixed bottom
  for (int node : rig.front_face)
    if (a.dofs.fixed_axes[static_cast<std::size_t>(node)] == 0) free_back.push_back(node);
  ASSERT_GE(free_back.size(), 10u);
  const std::vector<int> held{free_back[1], free_back[4]};
  for (int node : held) condensation.add_boundary_node(node);
  const Eigen::Vector3d tool = fem_pair_tool(0.0, 3e-3);
  const Triangle& triangle =
      a.surface.triangles[static_cast<std::size_t>(nearest_touchable_triangle(a, tool))];
  const PressingContact contact{{triangle[0], triangle[1], triangle[2]},
                                Eigen::Vector3d(0.2, 0.3, 0.5),
                                Eigen::Vector3d(3e-3, 0.4e-3, -0.2e-3)};
  AppliedLoads applied;  // on three back-face nodes, none held
  std::vector<double> forces;
  for (int node : {free_back[2], free_back[7], free_back[9]})
    for (int axis = 0; axis < 3; ++axis)
      if (!a.dofs.is_fixed(node, axis)) {
        applied.dofs.push_back(3 * node + axis);
        forces.push_back(0.3 * (axis + 1) - 0.1 * (node % 5));
      }
  applied.forces =
      Eigen::Map<const Eigen::VectorXd>(forces.data(), static_cast<Eigen::Index>(forces.size()));
  std::vector<int> prescribed;
  std::vector<double> values;
  Eigen::VectorXd held_displacement(0);
  std::vector<double> held_values;
  for (std::size_t k = 0; k < held.size(); ++k)
    for (int axis = 0; axis < 3; ++axis)
      if (!a.dofs.is_fixed(held[k], axis)) {
        prescribed.push_back(3 * held[k] + axis);
        values.push_back((k == 0 ? 1e-4 : -2e-4) * (axis + 1));
        held_values.push_back(values.back());
      }
  held_displacement = Eigen::Map<const Eigen::VectorXd>(
      held_values.data(), static_cast<Eigen::Index>(held_values.size()));
  for (int node : triangle)
    for (int axis = 0; axis < 3; ++axis)
      if (!a.dofs.is_fixed(node, axis)) {
        prescribed.push_back(3 * node + axis);
        values.push_back(contact.displacement[axis]);
      }
  ASSERT_EQ(applied.dofs.size(), 9u);
  ASSERT_EQ(held_values.size(), 6u);
  const StateSolution state =
      solve_state(columns, condensation, a.dofs, std::span(&contact, 1), held_displacement,
                  ContactModel::node_translation, applied);
  Eigen::VectorXd loads = Eigen::VectorXd::Zero(a.stiffness.rows());
  for (std::size_t k = 0; k < applied.dofs.size(); ++k)
    loads[applied.dofs[k]] = applied.forces[static_cast<Eigen::Index>(k)];
  const StaticSolution full =
      ConstrainedStaticSolver(a.stiffness, a.dofs, prescribed)
          .solve(Eigen::Map<const Eigen::VectorXd>(values.data(),
                                                   static_cast<Eigen::Index>(values.size())),
                 loads);

  const Eigen::Matrix3Xd u = displacement_of_nodes(columns, state, a.surface.nodes);
  double error = 0, largest = 0;
  for (std::size_t i = 0; i < a.surface.nodes.size(); ++i) {
    const Eigen::Vector3d expected = full.displacement.segment<3>(3 * a.surface.nodes[i]);
    largest = std::max(largest, expected.norm());
    error = std::max(error, (u.col(static_cast<Eigen::Index>(i)) - expected).norm());
  }
  EXPECT_LE(error, 1e-9 * largest);
  ASSERT_EQ(state.boundary_dofs.size(), held_values.size());
  for (std::size_t k = 0; k < state.boundary_dofs.size(); ++k)
    EXPECT_NEAR(state.boundary_forces[static_cast<Eigen::Index>(k)],
                full.reaction[state.boundary_dofs[k]], 1e-9 * full.reaction.cwiseAbs().maxCoeff());
  Eigen::Vector3d tool_force = Eigen::Vector3d::Zero();
  for (int k = 0; k < 3; ++k)
    for (int axis = 0; axis < 3; ++axis)
      if (!a.dofs.is_fixed(triangle[static_cast<std::size_t>(k)], axis))
        tool_force[axis] +=
            contact.weights[k] * full.reaction[3 * triangle[static_cast<std::size_t>(k)] + axis];
  EXPECT_LE((state.tool_forces.at(0) - tool_force).norm(), 1e-9 * tool_force.norm());
}

TEST(FemPairScene, TheServersForceAndBothBodiesShapesAreTheJointSparseSolves) {
  for (const double gap_mm : {0.0, 0.5}) {
    SCOPED_TRACE(gap_mm);
    FemPairRun run(fem_pair_scene(gap_mm, kFemPairInteraction));
    const testing::PairedBoxesRig rig(fem_pair_scene_options(gap_mm));
    ASSERT_EQ(rig.front.mesh.nodes, elastic_body(run.model, 0).mesh.nodes);
    ASSERT_EQ(rig.behind.mesh.nodes, elastic_body(run.model, 1).mesh.nodes);
    const Eigen::Vector3d tool = fem_pair_tool(gap_mm, 4e-3);
    const ForceSample felt = run.press(tool);
    const ExpectedPress expected = expected_press(rig, tool);

    // The pushes, by A's node: the scene found the same pushing nodes and pushes.
    const FemPairInteraction& pair = run.simulation.fem_pair(0);
    std::unordered_map<int, double> joint_push;  // by A's node
    for (std::size_t j = 0; j < expected.candidates.size(); ++j)
      if (const double push = expected.joint.pushes[static_cast<Eigen::Index>(j)]; push > 0)
        joint_push[expected.candidates[j].active] = push;
    const double push_scale = expected.joint.pushes.maxCoeff();
    ASSERT_GT(push_scale, 0);
    int pushing = 0;
    for (std::size_t j = 0; j < pair.collisions.size(); ++j)
      if (const double push = pair.contact.pushes[static_cast<Eigen::Index>(j)]; push > 0) {
        ++pushing;
        ASSERT_TRUE(joint_push.count(pair.collisions[j].active)) << pair.collisions[j].active;
        EXPECT_NEAR(push, joint_push.at(pair.collisions[j].active), 1e-9 * push_scale);
      }
    EXPECT_EQ(pushing, static_cast<int>(joint_push.size()));
    EXPECT_TRUE(run.simulation.condenses_over_support(0));
    EXPECT_FALSE(run.simulation.condenses_over_support(1));

    // The server's state: the tool's force with B's pushes applied to A.
    EXPECT_GT(expected.force.norm(), 0);
    const Eigen::Vector3d state_force = -run.fem(0).solve().tool_forces.at(0);
    EXPECT_LE((state_force - expected.force).norm(), 1e-9 * expected.force.norm());
    // The server's force, from the user's IR: B felt through A's M~ (and, across the gap,
    // the IR's rest forces: B holds the nodes that crossed it on its plane).
    EXPECT_LE((felt.force - expected.force).norm(), 1e-9 * expected.force.norm())
        << felt.force.transpose() << " vs " << expected.force.transpose();
    EXPECT_EQ(condensed_fem(run.simulation.ir(0)->ir).rest_forces.size() == 0, gap_mm == 0);
    RecordProperty(
        fmt::format("ir_force_relative_error_gap_{}mm", gap_mm),
        fmt::format("{:.2e}", (felt.force - expected.force).norm() / expected.force.norm()));
    // A shows B's support and B shows A's pushes.
    const auto [front_error, front_largest] =
        surface_difference(run.fem(0), rig.front, expected.joint.front);
    EXPECT_LE(front_error, 1e-9 * front_largest);
    const auto [behind_error, behind_largest] =
        surface_difference(run.fem(1), rig.behind, expected.joint.behind);
    EXPECT_GT(behind_largest, 0);
    EXPECT_LE(behind_error, 1e-9 * behind_largest);
  }
}

// The pair acts between A's stages, after its tools' contacts and before its IRs: the IR of
// the very step in which A starts pushing B condenses over B, not one a step later.
TEST(FemPairScene, TheStepInWhichAStartsPushingBuildsItsIrOverB) {
  FemPairRun run(fem_pair_scene(0.5, kFemPairInteraction));
  run.simulation.set_tool(0, fem_pair_tool(0.5, 4e-3));
  run.simulation.step(0);
  ASSERT_TRUE(run.simulation.condenses_over_support(0));
  const auto ir = run.simulation.ir(0);
  ASSERT_TRUE(ir);
  EXPECT_GT(condensed_fem(ir->ir).rest_forces.size(), 0)
      << "the first step's IR was built before B was folded in";
}

TEST(FemPairScene, TheClientFeelsBThroughAsIrAsTheServerDoes) {
  // Across a gap: the IR carries rest forces too.
  FemPairRun run(fem_pair_scene(0.5, kFemPairInteraction));
  const Eigen::Vector3d tool = fem_pair_tool(0.5, 4e-3);
  const ForceSample on_server = run.press(tool);
  const auto ir = run.simulation.ir(0);
  ASSERT_TRUE(ir);
  ASSERT_TRUE(run.simulation.condenses_over_support(0));
  // M~ whole through the wire, as the server sends an IR that condenses over a support.
  const IntermediateRepresentation received = wire::from_wire(wire::to_wire(ir->ir));
  ASSERT_GT(condensed_fem(received).rest_forces.size(), 0);
  EXPECT_EQ(condensed_fem(received).rest_forces, condensed_fem(ir->ir).rest_forces);
  const PreparedIR on_client = prepare_ir(received);
  EvaluationState state = make_evaluation_state(on_client);
  const ForceSample felt = evaluate_force(on_client, state, tool, {}, 1e-3);
  EXPECT_GT(on_server.force.norm(), 0);
  EXPECT_LE((felt.force - on_server.force).norm(), 1e-9 * on_server.force.norm());
  // And for another tool position within the same pushing set and patch.
  const Eigen::Vector3d moved = tool + Eigen::Vector3d(0.5e-3, 0.3e-3, -0.2e-3);
  run.simulation.set_tool(0, moved);
  run.simulation.step(2e-3);
  ASSERT_EQ(run.simulation.ir(0), ir);  // no rebuild: the sets stayed
  const ForceSample server_moved = run.simulation.force(0);
  EXPECT_LE((evaluate_force(on_client, state, moved, {}, 1e-3).force - server_moved.force).norm(),
            1e-9 * server_moved.force.norm());
}

TEST(FemPairScene, APushOnBFeelsMoreThanFreeAndLessThanFixed) {
  FemPairRun on_behind(fem_pair_scene(0.0, kFemPairInteraction));
  FemPairRun free(fem_pair_scene(0.0, ""));
  FemPairRun fixed(with_back_fixed(fem_pair_scene(0.0, ""), 0.0));
  for (const double depth : {1e-3, 4e-3, 8e-3}) {
    SCOPED_TRACE(depth);
    const Eigen::Vector3d tool = fem_pair_tool(0.0, depth);
    const double f_free = -free.press(tool).force.x();
    const double f_on_behind = -on_behind.press(tool).force.x();
    const double f_fixed = -fixed.press(tool).force.x();
    EXPECT_GT(f_free, 0);
    EXPECT_LT(f_free, f_on_behind);
    EXPECT_LT(f_on_behind, f_fixed);
  }
}

// The shipped scene (scenes/objects/fem_pair.yaml) with its two scripted surgeons, stepped
// every 10 ms (the bodies are static) to the middle of A's first hold: both press A, B
// gives way under A, and each feels more than on A alone (the scene without its interaction).
TEST(FemPairScene, TheShippedScenesSurgeonsFeelBThroughA) {
  const std::filesystem::path file = testing::source_path("scenes/objects/fem_pair.yaml");
  const Trajectory surgeon_a =
      load_trajectory(testing::source_path("scenes/objects/fem_pair/surgeon_a.yaml"));
  const Trajectory surgeon_b =
      load_trajectory(testing::source_path("scenes/objects/fem_pair/surgeon_b.yaml"));
  Scene alone_scene = load_scene(file);
  alone_scene.interactions.clear();
  FemPairRun on_behind(load_scene(file));
  FemPairRun alone(std::move(alone_scene));
  const double hold = 2.8;  // s: surgeon A 4 mm deep, surgeon B 3 mm deep and sliding
  for (FemPairRun* run : {&on_behind, &alone})
    for (double time = 0; time <= hold + 1e-9; time += 0.01) {
      run->simulation.set_tool(0, surgeon_a.position(time));
      run->simulation.set_tool(1, surgeon_b.position(time));
      run->simulation.step(time);
    }
  for (int user = 0; user < 2; ++user) {
    SCOPED_TRACE(user);
    ASSERT_TRUE(on_behind.simulation.pressing(user));
    EXPECT_EQ(on_behind.simulation.body_of(user), 0);
    const double felt = on_behind.simulation.force(user).force.z();
    const double without_b = alone.simulation.force(user).force.z();
    EXPECT_GT(without_b, 0);
    EXPECT_GT(felt, without_b);
    RecordProperty(fmt::format("user_{}_force_on_b_alone_n", user),
                   fmt::format("{:.4f} {:.4f}", felt, without_b));
  }
  EXPECT_TRUE(on_behind.simulation.condenses_over_support(0));
  const FemPairInteraction& pair = on_behind.simulation.fem_pair(0);
  EXPECT_GT((pair.contact.pushes.array() > 0).count(), 2);
  EXPECT_EQ(pair.failures, 0);
  // B sinks under A: its upper face's lowest point is below rest.
  const ElasticBody& b = elastic_body(on_behind.model, 1);
  EXPECT_LT(on_behind.fem(1).displacement_of(b.touchable_nodes).row(2).minCoeff(), -1e-4);
}

TEST(FemPairScene, RefusesPairsItCannotRunSayingWhere) {
  try {
    fem_pair_scene(0.0, std::string(kFemPairInteraction) + "haptic: {contact_model: point}\n");
    ADD_FAILURE() << "no error for the point contact model";
  } catch (const SceneError& error) {
    const std::string what = error.what();
    EXPECT_NE(what.find("fem-pair.yaml:"), std::string::npos) << what;
    EXPECT_NE(what.find("translation contact model only"), std::string::npos) << what;
  }
  // SceneSimulation says the same of a scene built in code.
  Scene scene = fem_pair_scene(0.0, kFemPairInteraction);
  scene.haptic.contact_model = ContactModel::point_constraint;
  EXPECT_THROW(FemPairRun{std::move(scene)}, Error);
}

}  // namespace
}  // namespace cohaptic
