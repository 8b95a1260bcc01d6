// Warming a sphere IR's contact solve to where the tools are now (the client does it as the IR
// arrives): the warmed start is the solution there (the full sparse FEM solve's force and the
// contact set a cold start reaches with an unlimited budget), a first tick from it changes no
// contact and needs a fraction of the work a cold first tick does, it is the same bit for bit
// when warmed again (a replay), and what cannot be warmed is left as it was.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <limits>
#include <vector>

#include "common/ir/warm_start_sphere_contact.h"
#include "common/model/sphere_contact_reference.h"
#include "common/sim/simulation.h"
#include "support/cube_scene.h"
#include "support/measures.h"
#include "support/unlimited_options.h"

namespace cohaptic {
namespace warm_start_tests {
namespace {

using testing::mm;
using testing::relative_error;

constexpr double kRadius = 0.1;  // [m], the sphere below

// The cube (8 mm between nodes) pressed by one 100 mm sphere, and the IR the server built for
// it 1 mm into the cube: the tool then goes 2.5 mm deeper before the IR reaches its client,
// and pushes a dozen more nodes.
struct PressedCube {
  testing::CubeRig rig{[] {
    testing::CubeSceneOptions options;
    options.divisions = 16;
    options.tools = "[{name: A, shape: sphere, radius: 100}]";
    return options;
  }()};
  Simulation simulation{rig.body, rig.model->obstacles, *rig.columns,
                        std::vector<ToolSpec>(1, rig.model->scene.tools[0]),
                        testing::unlimited_options(ContactModel::sphere, 0, 2)};
  const Eigen::Vector3d built_at = mm(1, 2, 99);
  const Eigen::Vector3d now = mm(1.5, 2, 96.5);
  PressedCube() {
    simulation.set_tool(0, built_at);
    simulation.step(0);
  }
  const PreparedIR& ir() const { return *simulation.ir(0); }
};

PressedCube& pressed_cube() {
  static PressedCube cube;
  return cube;
}

// The first tick's solve on `prepared` at `own` with `budget`: its force, its flags and what
// the solve spent.
struct FirstTick {
  ForceSample sample;
  UnilateralSolveResult solve;
  std::vector<int> members;
};

FirstTick first_tick(const PreparedIR& prepared, const Eigen::Vector3d& own, double budget) {
  EvaluationState state = make_evaluation_state(prepared);
  SphereContactState& sphere = *std::get<FemEvaluation>(state.body).sphere;
  // The solve's own accounting: a copy of the start solved as the tick solves it.
  sphere.work_budget = budget;
  FirstTick tick;
  tick.sample = evaluate_force(prepared, state, own, {}, 1e-3);
  IncrementalContactSolve replayed = std::get<PreparedFem>(prepared.body).sphere.start;
  tick.solve =
      replayed.solve(condensed_fem(prepared.ir).sphere->normal_compliance, sphere.clearance,
                     std::get<PreparedFem>(prepared.body).sphere.nonnegative_rows, budget);
  const std::span<const int> members = sphere.solve.members();
  tick.members.assign(members.begin(), members.end());
  std::sort(tick.members.begin(), tick.members.end());
  return tick;
}

TEST(WarmStartSphereContact, StartsTheFirstTickAtTheSolutionWhereTheToolIsNow) {
  PressedCube& cube = pressed_cube();
  const double unlimited = std::numeric_limits<double>::infinity();
  const FirstTick cold = first_tick(cube.ir(), cube.now, unlimited);

  PreparedIR warmed = cube.ir();
  ASSERT_TRUE(warm_start_sphere_contact(warmed, cube.now, {}));
  const FirstTick warm = first_tick(warmed, cube.now, unlimited);

  // The same answer as the cold start's, and the full sparse solve's.
  const SphereContactSolution reference = sphere_reactions_reference(
      cube.rig.body, {{cube.now, kRadius}},
      {cube.simulation.condensation().boundary_nodes(), cube.simulation.boundary_displacement()},
      nullptr, {});
  EXPECT_LE(relative_error(warm.sample.force, reference.reactions[0]), 1e-9);
  EXPECT_LE(relative_error(warm.sample.force, cold.sample.force), 1e-12);
  EXPECT_EQ(warm.members, cold.members);
  // From the warmed start the tick changes no contact: one pass, and a small part of the
  // cold start's work, which had dozens of nodes to take in.
  const std::span<const int> start = std::get<PreparedFem>(warmed.body).sphere.start.members();
  std::vector<int> warm_start(start.begin(), start.end());
  std::sort(warm_start.begin(), warm_start.end());
  EXPECT_EQ(warm_start, warm.members);
  EXPECT_GT(cold.members.size(),
            std::get<PreparedFem>(cube.ir().body).sphere.start.members().size() + 10);
  std::printf(
      "  first tick 2.5 mm deeper: cold %zu -> %zu contacts, %.0f multiply-adds; warm "
      "%.0f\n",
      std::get<PreparedFem>(cube.ir().body).sphere.start.members().size(), cold.members.size(),
      cold.solve.work, warm.solve.work);
  EXPECT_EQ(warm.solve.trials, 1);
  EXPECT_LT(warm.solve.work, 0.25 * cold.solve.work);
}

TEST(WarmStartSphereContact, IsTheSameBitForBitWhenWarmedAgain) {
  PressedCube& cube = pressed_cube();
  PreparedIR first = cube.ir(), second = cube.ir();
  ASSERT_TRUE(warm_start_sphere_contact(first, cube.now, {}));
  ASSERT_TRUE(warm_start_sphere_contact(second, cube.now, {}));
  const IncrementalContactSolve& a = std::get<PreparedFem>(first.body).sphere.start;
  const IncrementalContactSolve& b = std::get<PreparedFem>(second.body).sphere.start;
  ASSERT_EQ(std::vector<int>(a.members().begin(), a.members().end()),
            std::vector<int>(b.members().begin(), b.members().end()));
  EXPECT_EQ(Eigen::MatrixXd(a.factor()), Eigen::MatrixXd(b.factor()));
  EXPECT_EQ(std::vector<double>(a.member_pushes().begin(), a.member_pushes().end()),
            std::vector<double>(b.member_pushes().begin(), b.member_pushes().end()));
}

TEST(WarmStartSphereContact, LeavesWhatItCannotWarmAsItWas) {
  PressedCube& cube = pressed_cube();
  const auto members = [](const PreparedIR& prepared) {
    const std::span<const int> set = std::get<PreparedFem>(prepared.body).sphere.start.members();
    return std::vector<int>(set.begin(), set.end());
  };
  PreparedIR untouched = cube.ir();
  EXPECT_FALSE(warm_start_sphere_contact(
      untouched, Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()), {}));
  EXPECT_EQ(members(untouched), members(cube.ir()));
  // An IR of another contact model has no contact solve to warm.
  PreparedIR other_model = cube.ir();
  std::get<CondensedFemIr>(other_model.ir.body).contact_model = ContactModel::point_constraint;
  EXPECT_FALSE(warm_start_sphere_contact(other_model, cube.now, {}));
  EXPECT_EQ(members(other_model), members(cube.ir()));
}

}  // namespace
}  // namespace warm_start_tests
}  // namespace cohaptic
