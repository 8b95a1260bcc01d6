// A rigid obstacle under the sphere contact model: a frictionless unilateral constraint
// solved together with the spheres' pushes (sphere_state_solve.h). The simulation's state
// and every IR's force must equal the full sparse solve of the same unilateral problem
// (SphereContactReference with the obstacles' constraints), whatever path the tools took
// to their positions: pressed in one step, approached in ten, or slid in from the side.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "common/contact/obstacle_constraints.h"
#include "common/model/sphere_contact_reference.h"
#include "common/sim/simulation.h"
#include "proto/wire/ir_convert.h"
#include "support/brain_scene.h"
#include "support/cube_scene.h"
#include "support/evaluate_static.h"
#include "support/expect_refused.h"
#include "support/measures.h"
#include "support/unlimited_options.h"

namespace cohaptic {
namespace {

using testing::expect_refused;
using testing::mm;
using testing::relative_error;

// The tools' path to their final positions: each tool moves in `steps` equal steps from
// `from` (its own) to `to`, then the simulation settles (steps until its sets stop changing).
void move(Simulation& simulation, const std::vector<Eigen::Vector3d>& from,
          const std::vector<Eigen::Vector3d>& to, int steps, double& time) {
  for (int k = 1; k <= steps; ++k) {
    const double s = static_cast<double>(k) / steps;
    for (std::size_t u = 0; u < to.size(); ++u)
      simulation.set_tool(static_cast<int>(u), (1 - s) * from[u] + s * to[u]);
    simulation.step(time += 1e-3);
  }
  for (int settling = 0; settling < 10 && simulation.step(time += 1e-3).rebuilt; ++settling) {
  }
}

struct PathResult {
  std::vector<Eigen::Vector3d>
      server;  ///< the simulation's state: each sphere's force on the object
  std::vector<Eigen::Vector3d>
      ir;                  ///< each user's IR evaluated at the tools: the force on the tool
  int obstacle_rows = 0;   ///< in user 0's IR
  int obstacle_nodes = 0;  ///< the obstacles push in the state
};

PathResult result_of(Simulation& simulation, const std::vector<Eigen::Vector3d>& tools) {
  PathResult result;
  const StateSolution state = simulation.solve();
  result.server = state.tool_forces;
  for (int user = 0; user < static_cast<int>(tools.size()); ++user) {
    const PreparedIR& prepared = *simulation.ir(user);
    std::vector<Eigen::Vector3d> remotes;
    for (int r = 0; r < remote_count(prepared.ir); ++r)
      remotes.push_back(tools[static_cast<std::size_t>(remote_user(prepared.ir, r))]);
    const ForceSample sample =
        testing::evaluate_static(prepared, tools[static_cast<std::size_t>(user)], remotes);
    EXPECT_FALSE(sample.flags & (kOutsidePatch | kContactUnresolved | kNonFinite))
        << "user " << user;
    result.ir.push_back(sample.force);
  }
  const SphereContactIr& sphere = *condensed_fem(simulation.ir(0)->ir).sphere;
  result.obstacle_rows = static_cast<int>(
      (sphere.obstacle_gaps.array() < std::numeric_limits<double>::infinity()).count());
  return result;
}

// Each path's server forces and IR forces against the reference reactions (forces on the
// tools), to `tolerance` relative.
void expect_equal_to_reference(const std::vector<PathResult>& paths,
                               const std::vector<std::string>& names,
                               const SphereContactSolution& reference, double tolerance) {
  for (std::size_t p = 0; p < paths.size(); ++p)
    for (std::size_t u = 0; u < reference.reactions.size(); ++u) {
      const Eigen::Vector3d expected = reference.reactions[u];
      ASSERT_GT(expected.norm(), 0) << "tool " << u << " presses nothing";
      EXPECT_LE(relative_error(-paths[p].server[u], expected), tolerance)
          << names[p] << ", server, tool " << u;
      EXPECT_LE(relative_error(paths[p].ir[u], expected), tolerance)
          << names[p] << ", IR, tool " << u;
    }
}

int obstacle_contacts(const SphereContactSolution& solution) {
  int count = 0;
  for (std::size_t i = 0; i < solution.candidates.size(); ++i)
    count +=
        solution.constraints[i].obstacle >= 0 && solution.pushes[static_cast<Eigen::Index>(i)] > 0;
  return count;
}

// The cube with a wall 0.4 mm beside its side x = +65 mm, and one 30 mm sphere tool.
testing::CubeRig& wall_rig() {
  static testing::CubeRig rig([] {
    testing::CubeSceneOptions scene;
    scene.divisions = 8;
    scene.tools = "[{name: A, shape: sphere, radius: 30}]";
    scene.obstacles = "{name: wall, plane: {point: [65.4, 0, 0], normal: [-1, 0, 0]}}";
    return scene;
  }());
  return rig;
}

TEST(SphereObstacle, ABulgeSlidesOnAWallTheSameInOneStepOrManyAndAsTheFullSparseSolve) {
  // A 30 mm sphere presses the top of the cube 6 mm deep, 25 mm from its side x = +65 mm;
  // the side bulges out and meets the wall, while its nodes move down.
  testing::CubeRig& rig = wall_rig();
  const ElasticBody& body = rig.body;
  const std::vector<SphereConstraint> obstacles =
      obstacle_constraints(body.mesh, body.surface, body.dofs, rig.model->obstacles);
  const std::vector<Eigen::Vector3d> deep = {mm(40, 0, 24)}, shallow = {mm(40, 0, 28)};
  const auto run = [&](const std::vector<std::pair<std::vector<Eigen::Vector3d>, int>>& legs) {
    Simulation simulation(body, rig.model->obstacles, *rig.columns, rig.model->scene.tools,
                          testing::unlimited_options(ContactModel::sphere));
    double time = 0;
    std::vector<Eigen::Vector3d> at = legs.front().first;
    for (const auto& [to, steps] : legs) {
      move(simulation, at, to, steps, time);
      at = to;
    }
    PathResult result = result_of(simulation, at);
    result.obstacle_nodes = simulation.step(time += 1e-3).obstacle_nodes;
    return result;
  };
  const std::vector<Eigen::Vector3d> above = {mm(40, 0, 31)}, aside = {mm(0, 0, 24.5)};
  const std::vector<PathResult> paths = {run({{deep, 1}}), run({{above, 1}, {deep, 10}}),
                                         run({{aside, 1}, {deep, 10}})};
  const std::vector<std::string> names = {"one step", "ten steps down", "slid in from the side"};

  Eigen::VectorXd u;
  const SphereContactSolution reference =
      sphere_reactions_reference(body, {{deep[0], 30e-3}}, {}, &u, obstacles);
  expect_equal_to_reference(paths, names, reference, 1e-9);
  ASSERT_GE(obstacle_contacts(reference), 3) << "the bulge should reach the wall";
  for (const PathResult& path : paths) {
    EXPECT_EQ(path.obstacle_nodes, obstacle_contacts(reference));
    EXPECT_GE(path.obstacle_rows, path.obstacle_nodes) << "the IR carries the wall's nodes";
  }
  // The wall's nodes sit on it and slide along it (down, with the top pressed in).
  double slid = 0;
  for (std::size_t i = 0; i < reference.candidates.size(); ++i) {
    if (reference.constraints[i].obstacle < 0 ||
        !(reference.pushes[static_cast<Eigen::Index>(i)] > 0))
      continue;
    const int node = reference.candidates[i];
    EXPECT_NEAR(body.mesh.nodes(0, node) + u[3 * node], 65.4e-3, 1e-12) << "node " << node;
    slid = std::max(slid, std::hypot(u[3 * node + 1], u[3 * node + 2]));
  }
  EXPECT_GT(slid, 1e-5) << "the nodes on the wall should slide along it";

  // Back up to a shallow press: the wall lets go of every node (it never pulls), and the
  // force is that of pressing there directly.
  const PathResult released = run({{deep, 1}, {shallow, 5}});
  const SphereContactSolution shallow_reference =
      sphere_reactions_reference(body, {{shallow[0], 30e-3}}, {}, nullptr, obstacles);
  EXPECT_EQ(obstacle_contacts(shallow_reference), 0);
  EXPECT_EQ(released.obstacle_nodes, 0);
  expect_equal_to_reference({released}, {"backed up"}, shallow_reference, 1e-9);
  std::printf(
      "  %d nodes on the wall, slid up to %.4f mm along it; |F| %.4f N deep, %.4f N backed up\n",
      obstacle_contacts(reference), slid * 1e3, reference.reactions[0].norm(),
      shallow_reference.reactions[0].norm());
}

TEST(SphereObstacle, TheIrsWallRowsTravelBitForBitAndTheirInconsistenciesAreRefused) {
  testing::CubeRig& rig = wall_rig();
  Simulation simulation(rig.body, rig.model->obstacles, *rig.columns, rig.model->scene.tools,
                        testing::unlimited_options(ContactModel::sphere));
  const Eigen::Vector3d tool = mm(40, 0, 24);
  simulation.set_tool(0, tool);
  simulation.step(0);
  const IntermediateRepresentation& ir = simulation.ir(0)->ir;
  const Eigen::VectorXd& gaps = condensed_fem(ir).sphere->obstacle_gaps;
  const wire::IntermediateRepresentation valid = wire::to_wire(ir);
  ASSERT_GT(valid.fem().sphere().obstacle_rows_size(), 0);
  const IntermediateRepresentation back = wire::from_wire(valid);
  EXPECT_TRUE(condensed_fem(back).sphere->obstacle_gaps == gaps);
  EXPECT_EQ(testing::evaluate_static(prepare_ir(back), tool, {}).force,
            testing::evaluate_static(*simulation.ir(0), tool, {}).force);

  wire::IntermediateRepresentation w = valid;
  w.mutable_fem()->mutable_sphere()->add_obstacle_gaps(1e-3);
  expect_refused(w, "sphere.obstacle_rows has");
  w = valid;
  w.mutable_fem()->mutable_sphere()->set_obstacle_rows(
      0, static_cast<std::uint32_t>(w.fem().row_node_count()));
  expect_refused(w, "is not an ascending row node");
  w = valid;
  w.mutable_fem()->mutable_sphere()->set_obstacle_gaps(0, std::nan(""));
  expect_refused(w, "sphere.obstacle_gaps[0] is not finite");
  IntermediateRepresentation copy = ir;
  SphereContactIr& sphere = *condensed_fem(copy).sphere;
  Eigen::Index row = 0;
  while (std::isinf(sphere.obstacle_gaps[row])) ++row;
  sphere.normals.col(row).setZero();
  expect_refused(wire::to_wire(copy), "obstacle gap is");
}

TEST(SphereObstacle, TheBrainOnItsSkullPressedInOneStepOrTenEqualsTheFullSparseSolve) {
  // The demo's two spatula tips at their deepest (scenes/brain/surgeon_*.yaml), the skull
  // holding the brain as they push.
  const Model model = build_model(testing::brain_scene(testing::kCoarseBrainMesh));
  const ElasticBody& body = single_elastic_body(model);
  ASSERT_FALSE(model.obstacles.empty());
  ComplianceColumns columns(body.free_factor, body.dofs, body.surface.nodes);
  const std::vector<Eigen::Vector3d> deepest = {mm(-15.943, -75.736, -49.285),
                                                mm(0.119, -85.715, -30.175)};
  const Eigen::Vector3d lift = mm(0, 0, 15);
  const auto run = [&](int steps) {
    Simulation simulation(body, model.obstacles, columns, model.scene.tools,
                          testing::unlimited_options(ContactModel::sphere));
    double time = 0;
    if (steps == 1) {
      move(simulation, deepest, deepest, 1, time);
    } else {  // from the tools' approach: A from above, B from below
      const std::vector<Eigen::Vector3d> start = {deepest[0] + lift, deepest[1] - lift};
      move(simulation, start, start, 1, time);
      move(simulation, start, deepest, steps, time);
    }
    PathResult result = result_of(simulation, deepest);
    result.obstacle_nodes = simulation.step(time += 1e-3).obstacle_nodes;
    return result;
  };
  const std::vector<PathResult> paths = {run(1), run(10)};
  std::vector<PressedTool> pressed;
  for (std::size_t u = 0; u < deepest.size(); ++u)
    pressed.push_back({deepest[u], model.scene.tools[u].radius});
  const SphereContactSolution reference = sphere_reactions_reference(
      body, pressed, {}, nullptr,
      obstacle_constraints(body.mesh, body.surface, body.dofs, model.obstacles));
  expect_equal_to_reference(paths, {"one step", "ten steps"}, reference, 1e-9);
  EXPECT_GT(obstacle_contacts(reference), 0) << "the skull should hold some of the brain";
  for (const PathResult& path : paths) EXPECT_EQ(path.obstacle_nodes, obstacle_contacts(reference));
  std::printf("  %d nodes on the skull; A %.2f mN, B %.2f mN\n", obstacle_contacts(reference),
              reference.reactions[0].norm() * 1e3, reference.reactions[1].norm() * 1e3);
}

}  // namespace
}  // namespace cohaptic
