// The intermediate representation and its force evaluator against the full sparse FEM
// solve: one and two users, both contact models, sliding within the patch, held boundary
// nodes, float32 storage, and what happens at edges, past the patch and with bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <random>

#include "common/contact/nearest_surface_nodes.h"
#include "common/ir/build_ir.h"
#include "common/model/static_contact.h"
#include "common/scene/load_scene.h"
#include "common/sim/simulation.h"
#include "support/cube_scene.h"
#include "support/evaluate_static.h"
#include "support/measures.h"
#include "support/unlimited_options.h"

namespace cohaptic {
namespace {

using testing::mm;
using testing::relative_error;
using testing::unlimited_options;

using Rig = testing::CubeRig;

Rig& shared_cube() {
  static Rig rig;
  return rig;
}

// The full sparse solve with all `tools` pressing and the simulation's held nodes.
std::vector<Eigen::Vector3d> reference_forces(const Model& model, const Simulation& simulation,
                                              const std::vector<Eigen::Vector3d>& tools,
                                              ContactModel contact_model) {
  const ElasticBody& body = single_elastic_body(model);
  std::vector<PressedTool> pressed;
  for (const Eigen::Vector3d& p : tools) pressed.push_back({p, 0});
  const HeldNodes held{simulation.condensation().boundary_nodes(),
                       simulation.boundary_displacement()};
  std::vector<Eigen::Vector3d> forces;
  for (const ToolReaction& r :
       contact_reactions_reference(body, find_tool_contacts(body, pressed), held, contact_model))
    forces.push_back(r.reaction);
  return forces;
}

// Whether the IR of `user` holds the triangles the tools now press (own within the patch,
// remote on its IR triangle): then the evaluator must be exact.
bool ir_covers(const Model& model, const PreparedIR& prepared,
               const std::vector<Eigen::Vector3d>& tools, int user) {
  const ElasticBody& body = single_elastic_body(model);
  const auto surface_triangle = [&](const Eigen::Vector3d& p) {
    return nearest_triangle(body.mesh, body.surface, body.normals, body.touchable_triangles, p)
        .triangle;
  };
  bool own = false;
  for (const IrTriangle& tri : condensed_fem(prepared.ir).patch)
    own |= tri.surface_index == surface_triangle(tools[user]);
  for (const IrRemoteContact& remote : condensed_fem(prepared.ir).remotes) {
    const Triangle& t = body.surface.triangles[surface_triangle(tools[remote.user])];
    for (int k = 0; k < 3; ++k)
      if (body.mesh.node_tags[t[k]] != condensed_fem(prepared.ir).node_ids[remote.nodes[k]])
        return false;
  }
  return own;
}

void two_users_match_the_full_solve(ContactModel contact_model, int step_delay_nodes) {
  Rig& rig = shared_cube();
  const Model& model = *rig.model;
  Simulation simulation(single_elastic_body(model), model.obstacles, *rig.columns,
                        std::vector<ToolSpec>(2),
                        unlimited_options(contact_model, step_delay_nodes));
  const std::vector<Eigen::Vector3d> start = {mm(-20, 5, -4), mm(25, -5, -3)};
  simulation.set_tool(0, start[0]);
  simulation.set_tool(1, start[1]);
  simulation.step(0);
  ASSERT_TRUE(simulation.pressing(0) && simulation.pressing(1));

  std::mt19937 rng(5);
  std::uniform_real_distribution<double> jitter(-3, 3), depth(0.5, 6);
  int checked = 0;
  double worst = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const std::vector<Eigen::Vector3d> tools = {start[0] + mm(jitter(rng), jitter(rng), 0),
                                                start[1] + mm(jitter(rng), jitter(rng), 0)};
    std::vector<Eigen::Vector3d> pressed = tools;
    pressed[0].z() = -depth(rng) * 1e-3;
    pressed[1].z() = -depth(rng) * 1e-3;
    // A tool moved onto a held node, or outside its IR's triangles: not this test's subject.
    if (!ir_covers(model, *simulation.ir(0), pressed, 0) &&
        !ir_covers(model, *simulation.ir(1), pressed, 1))
      continue;
    std::vector<Eigen::Vector3d> expected;
    try {
      expected = reference_forces(model, simulation, pressed, contact_model);
    } catch (const Error&) {
      continue;
    }
    for (int user = 0; user < 2; ++user) {
      const PreparedIR& prepared = *simulation.ir(user);
      if (!ir_covers(model, prepared, pressed, user)) continue;
      const Eigen::Vector3d remote = pressed[1 - user];
      const ForceSample sample =
          testing::evaluate_static(prepared, pressed[user], std::span(&remote, 1));
      ASSERT_TRUE(sample.flags & kInContact);
      worst = std::max(worst, relative_error(sample.force, expected[user]));
      EXPECT_LE(relative_error(sample.force, expected[user]), 1e-9)
          << "trial " << trial << " user " << user;
      ++checked;
    }
  }
  std::printf("  %s, %d held nodes: %d evaluations checked, worst relative error %.2e\n",
              contact_model == ContactModel::node_translation ? "translation" : "point",
              step_delay_nodes, checked, worst);
  EXPECT_GE(checked, 10);
}

TEST(IntermediateRepresentation, TwoUsersEqualTheFullSolveWithBothTools) {
  two_users_match_the_full_solve(ContactModel::node_translation, 0);
}
TEST(IntermediateRepresentation, TwoUsersEqualTheFullSolveWithThePointModel) {
  two_users_match_the_full_solve(ContactModel::point_constraint, 0);
}
TEST(IntermediateRepresentation, TwoUsersEqualTheFullSolveWithHeldBoundaryNodes) {
  two_users_match_the_full_solve(ContactModel::node_translation, 150);
  two_users_match_the_full_solve(ContactModel::point_constraint, 150);
}

// B truncation drops the held nodes whose columns of M_CB are weak: at threshold 0 the IR is
// the untruncated one bit for bit; above it the kept columns are the same numbers, the
// dropped nodes are exactly those below the threshold, and the force changes by exactly
// the dropped columns times their displacements.
// The step's stages run in order: the IRs are built from a held set updated for them, once.
TEST(IntermediateRepresentation, AreBuiltOnlyFromAHeldSetUpdatedForThem) {
  Rig& rig = shared_cube();
  const Model& model = *rig.model;
  Simulation simulation(single_elastic_body(model), model.obstacles, *rig.columns,
                        std::vector<ToolSpec>(1),
                        unlimited_options(ContactModel::node_translation, 0));
  simulation.set_tool(0, mm(-20, 5, -4));
  EXPECT_THROW(simulation.build_irs(0), Error);
  simulation.update_held_set();
  EXPECT_TRUE(simulation.build_irs(0).rebuilt);
  ASSERT_TRUE(simulation.ir(0));
  EXPECT_THROW(simulation.build_irs(0.001), Error);
  EXPECT_FALSE(simulation.step(0.001).rebuilt) << "nothing moved: the IR stands";
}

TEST(IntermediateRepresentation, BoundaryTruncationDropsOnlyWeakColumns) {
  Rig& rig = shared_cube();
  const Model& model = *rig.model;
  const ElasticBody& body = single_elastic_body(model);
  const Eigen::Vector3d tool = mm(4, -1, -2);
  const UserTool user{0, tool, 0, nearest_touchable_triangle(body, tool), {}};
  std::vector<bool> under_tool(static_cast<std::size_t>(body.mesh.node_count()), false);
  for (int v : body.surface.triangles[user.nearest_triangle]) under_tool[v] = true;
  IncrementalCondensation condensation(*rig.columns, body.dofs);
  const std::vector<Eigen::Vector3d> around = {tool};
  std::vector<int> held =
      nearest_surface_nodes(body.mesh, body.surface, body.dofs, around, 200, under_tool);
  held.erase(held.begin(), held.begin() + 20);  // leave the patch's neighbourhood free
  condensation.set_boundary_nodes(held);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> uniform(-1e-3, 1e-3);
  std::vector<Eigen::Vector3d> held_displacement;
  for (std::size_t i = 0; i < held.size(); ++i)
    held_displacement.emplace_back(uniform(rng), uniform(rng), uniform(rng));
  const std::vector<UserTool> users = {user};

  const auto build = [&](double threshold) {
    IrBuildOptions options;
    options.boundary_truncation = threshold;
    return build_ir(body, condensation, users, 0, held_displacement, options, 1, 0.0);
  };
  const IntermediateRepresentation full = build(0.0);
  EXPECT_EQ(condensed_fem(full).node_count(),
            condensed_fem(full).row_node_count + static_cast<int>(held.size()));
  const IntermediateRepresentation zero = build(0.0);
  EXPECT_EQ(condensed_fem(zero).m_tilde, condensed_fem(full).m_tilde);
  EXPECT_EQ(condensed_fem(zero).node_ids, condensed_fem(full).node_ids);

  const double threshold = 0.05;
  const IntermediateRepresentation cut = build(threshold);
  ASSERT_LT(condensed_fem(cut).node_count(), condensed_fem(full).node_count());
  ASSERT_GT(condensed_fem(cut).node_count(), condensed_fem(full).row_node_count);
  EXPECT_LT(cut.size_bytes(), full.size_bytes());
  const Eigen::Index contact = condensed_fem(full).m_tilde.rows();
  EXPECT_EQ(condensed_fem(cut).m_tilde.leftCols(contact),
            condensed_fem(full).m_tilde.leftCols(contact));

  // Each held node's coupling (norm of its three columns), kept or not.
  std::vector<double> coupling;
  for (std::size_t b = 0; b < held.size(); ++b)
    coupling.push_back(condensed_fem(full)
                           .m_tilde.middleCols(contact + 3 * static_cast<Eigen::Index>(b), 3)
                           .norm());
  const double strongest = *std::max_element(coupling.begin(), coupling.end());
  const Eigen::VectorXd u_c = Eigen::VectorXd::NullaryExpr(contact, [&] { return uniform(rng); });
  Eigen::VectorXd dropped_force = Eigen::VectorXd::Zero(contact);
  std::size_t next_kept = static_cast<std::size_t>(condensed_fem(cut).row_node_count);
  for (std::size_t b = 0; b < held.size(); ++b) {
    const std::int64_t tag = body.mesh.node_tags[held[b]];
    const bool kept = next_kept < condensed_fem(cut).node_ids.size() &&
                      condensed_fem(cut).node_ids[next_kept] == tag;
    EXPECT_EQ(kept, coupling[b] >= threshold * strongest) << "node " << tag;
    if (kept) {
      ++next_kept;
    } else {
      dropped_force +=
          condensed_fem(full).m_tilde.middleCols(contact + 3 * static_cast<Eigen::Index>(b), 3) *
          condensed_fem(full).boundary_displacement.segment<3>(3 * static_cast<Eigen::Index>(b));
    }
  }
  EXPECT_EQ(next_kept, condensed_fem(cut).node_ids.size());
  Eigen::VectorXd full_u(condensed_fem(full).m_tilde.cols()),
      cut_u(condensed_fem(cut).m_tilde.cols());
  full_u << u_c, condensed_fem(full).boundary_displacement;
  cut_u << u_c, condensed_fem(cut).boundary_displacement;
  const Eigen::VectorXd difference =
      condensed_fem(full).m_tilde * full_u - condensed_fem(cut).m_tilde * cut_u;
  EXPECT_LE((difference - dropped_force).norm(),
            1e-12 * (condensed_fem(full).m_tilde * full_u).norm());
  EXPECT_GT(dropped_force.norm(), 0.0);
  std::printf(
      "  B truncation at %.2f keeps %d of %zu held nodes: %zu -> %zu bytes, dropped force %.3g of "
      "%.3g N\n",
      threshold, condensed_fem(cut).node_count() - condensed_fem(cut).row_node_count, held.size(),
      full.size_bytes(), cut.size_bytes(), dropped_force.norm(),
      (condensed_fem(full).m_tilde * full_u).norm());
}

TEST(IntermediateRepresentation, EachUserFeelsTheOther) {
  Rig& rig = shared_cube();
  const auto force_alone_and_together = [&](int user) {
    Simulation alone(rig.body, rig.model->obstacles, *rig.columns, std::vector<ToolSpec>(2),
                     unlimited_options(ContactModel::node_translation));
    Simulation together(rig.body, rig.model->obstacles, *rig.columns, std::vector<ToolSpec>(2),
                        unlimited_options(ContactModel::node_translation));
    alone.set_tool(user, user == 0 ? mm(-12, 0, -5) : mm(12, 0, -5));
    together.set_tool(0, mm(-12, 0, -5));
    together.set_tool(1, mm(12, 0, -5));
    alone.step(0);
    together.step(0);
    return std::make_pair(alone.force(user).force, together.force(user).force);
  };
  for (int user = 0; user < 2; ++user) {
    const auto [alone, together] = force_alone_and_together(user);
    // The other tool sinks the surface nearby: this one needs less force for the same depth.
    EXPECT_LT(together.z(), alone.z());
    EXPECT_GT((alone - together).norm(), 0.05 * alone.norm()) << "user " << user;
  }
}

// Two tools on one triangle (or on two sharing a node): a node cannot follow both. As the
// client leaves out a remote tool whose triangle overlaps its own (kRemoteOverlap), the
// server's state (what the live view draws, and the held nodes' displacement under a step
// delay) leaves out the later tool, and the earlier one presses as if alone. A node listed
// twice would make the condensed compliance singular and fail every step a browser watched.
TEST(IntermediateRepresentation, TwoToolsOnOneTriangleSolveTheStateWithTheEarlierAsIfAlone) {
  Rig& rig = shared_cube();
  Simulation alone(rig.body, rig.model->obstacles, *rig.columns, std::vector<ToolSpec>(2),
                   unlimited_options(ContactModel::node_translation));
  Simulation together(rig.body, rig.model->obstacles, *rig.columns, std::vector<ToolSpec>(2),
                      unlimited_options(ContactModel::node_translation));
  alone.set_tool(0, mm(1, 1, -2));
  together.set_tool(0, mm(1, 1, -2));
  together.set_tool(1, mm(1.5, 1.2, -2.5));
  alone.step(0);
  together.step(0);
  ASSERT_TRUE(together.pressing(0) && together.pressing(1));
  StateSolution state;
  ASSERT_NO_THROW(state = together.solve());
  const StateSolution reference = alone.solve();
  ASSERT_EQ(state.tool_forces.size(), 1u) << "the later tool is left out";
  EXPECT_GT(reference.tool_forces[0].norm(), 0.0);
  EXPECT_LE((state.tool_forces[0] - reference.tool_forces[0]).norm(),
            1e-9 * reference.tool_forces[0].norm());
}

// Two remote tools on one triangle, away from the own tool: the client leaves out the later
// remote (kRemoteOverlap) and still feels its own press. With both in its system the node
// listed twice made it singular, and the own tool's force was zero (kNonFinite).
TEST(IntermediateRepresentation, TwoRemotesOnOneTriangleLeaveTheOwnForceResolved) {
  Rig& rig = shared_cube();
  Simulation simulation(rig.body, rig.model->obstacles, *rig.columns, std::vector<ToolSpec>(3),
                        unlimited_options(ContactModel::node_translation));
  simulation.set_tool(0, mm(-20, 5, -3));
  simulation.set_tool(1, mm(20, 5, -3));
  simulation.set_tool(2, mm(20.5, 5.2, -3.5));
  simulation.step(0);
  const ForceSample own = simulation.force(0);
  EXPECT_EQ(own.flags & kNonFinite, 0u);
  EXPECT_NE(own.flags & kRemoteOverlap, 0u);
  EXPECT_GT(own.force.norm(), 0.0);
}

TEST(IntermediateRepresentation, SlidingWithinThePatchStaysExact) {
  Rig& rig = shared_cube();
  const Model& model = *rig.model;
  Simulation simulation(single_elastic_body(model), model.obstacles, *rig.columns,
                        std::vector<ToolSpec>(1),
                        unlimited_options(ContactModel::node_translation, 0, 2));
  simulation.set_tool(0, mm(1, 2, -3));
  simulation.step(0);
  const PreparedIR& prepared = *simulation.ir(0);
  int triangles_visited = 0, previous = -1;
  for (double x = 1; x <= 20; x += 0.5) {
    const std::vector<Eigen::Vector3d> tool = {mm(x, 2 + 0.3 * x, -3)};
    if (!ir_covers(model, prepared, tool, 0)) break;
    const ForceSample sample = testing::evaluate_static(prepared, tool[0], {});
    EXPECT_LE(relative_error(sample.force, reference_forces(model, simulation, tool,
                                                            ContactModel::node_translation)[0]),
              1e-9)
        << "x = " << x;
    if (sample.triangle != previous) ++triangles_visited;
    previous = sample.triangle;
  }
  EXPECT_GE(triangles_visited, 3) << "the slide should cross several patch triangles";
}

TEST(IntermediateRepresentation, Float32StorageStaysCloseToFloat64) {
  Rig& rig = shared_cube();
  for (ContactModel contact_model :
       {ContactModel::node_translation, ContactModel::point_constraint}) {
    Simulation f64(rig.body, rig.model->obstacles, *rig.columns, std::vector<ToolSpec>(2),
                   unlimited_options(contact_model, 300));
    Simulation f32(rig.body, rig.model->obstacles, *rig.columns, std::vector<ToolSpec>(2),
                   unlimited_options(contact_model, 300, 1, IrPrecision::f32));
    for (Simulation* s : {&f64, &f32}) {
      s->set_tool(0, mm(-20, 5, -4));
      s->set_tool(1, mm(25, -5, -3));
      s->step(0);
    }
    EXPECT_LT(static_cast<double>(f32.ir(0)->ir.size_bytes()),
              0.6 * static_cast<double>(f64.ir(0)->ir.size_bytes()));
    for (int user = 0; user < 2; ++user) {
      const double error = relative_error(f32.force(user).force, f64.force(user).force);
      std::printf("  f32 vs f64 (%s, |B| 300): relative force difference %.2e\n",
                  contact_model == ContactModel::node_translation ? "translation" : "point", error);
      EXPECT_LE(error, 1e-4);
      EXPECT_GT(error, 0.0) << "float32 storage that changes nothing is not float32";
    }
  }
}

// Largest change of the force between consecutive samples of a slide across the front
// face, 3 mm deep, with samples `step` mm apart, staying inside the IR's patch.
double largest_change_along_slide(const PreparedIR& prepared, double step, double& peak) {
  double largest = 0;
  peak = 0;
  Eigen::Vector3d previous = testing::evaluate_static(prepared, mm(0.5, 0.4, -3), {}).force;
  for (double x = 0.5 + step; x <= 12; x += step) {
    const ForceSample sample = testing::evaluate_static(prepared, mm(x, 0.4 + 0.4 * x, -3), {});
    if (sample.flags & kOutsidePatch) break;
    largest = std::max(largest, (sample.force - previous).norm());
    peak = std::max(peak, sample.force.norm());
    previous = sample.force;
  }
  return largest;
}

TEST(IntermediateRepresentation, NodeTranslationJumpsAtEdgesThePointModelDoesNot) {
  // A continuous force's largest step-to-step change shrinks with the step; a jump does not.
  Rig& rig = shared_cube();
  std::printf(
      "  tool sliding 3 mm deep across several triangles (patch rings 2), largest change between "
      "samples:\n");
  for (ContactModel contact_model :
       {ContactModel::node_translation, ContactModel::point_constraint}) {
    Simulation simulation(rig.body, rig.model->obstacles, *rig.columns, std::vector<ToolSpec>(1),
                          unlimited_options(contact_model, 0, 2));
    simulation.set_tool(0, mm(0.5, 0.4, -3));
    simulation.step(0);
    double peak = 0;
    const double coarse = largest_change_along_slide(*simulation.ir(0), 0.2, peak);
    const double fine = largest_change_along_slide(*simulation.ir(0), 0.02, peak);
    std::printf(
        "    %-11s %.3f N with 0.2 mm steps, %.3f N with 0.02 mm steps (peak force %.2f N)\n",
        contact_model == ContactModel::node_translation ? "translation" : "point", coarse, fine,
        peak);
    if (contact_model == ContactModel::node_translation) {
      EXPECT_GT(fine, 0.5 * coarse) << "node translation switches nodes at an edge: a jump";
      EXPECT_LT(fine, 0.25 * peak) << "but the jump is bounded";
    } else {
      EXPECT_LT(fine, 0.5 * coarse) << "the point model is continuous across edges";
    }
  }
}

TEST(IntermediateRepresentation, PastThePatchTheForceIsHeldAndTheNextIrCatchesUp) {
  Rig& rig = shared_cube();
  const Model& model = *rig.model;
  Simulation simulation(single_elastic_body(model), model.obstacles, *rig.columns,
                        std::vector<ToolSpec>(1),
                        unlimited_options(ContactModel::point_constraint, 0, 0));
  simulation.set_tool(0, mm(1, 1, -3));
  simulation.step(0);
  const std::shared_ptr<const PreparedIR> old_ir = simulation.ir(0);
  Eigen::Vector3d previous = testing::evaluate_static(*old_ir, mm(1, 1, -3), {}).force;
  double largest_jump = 0;
  bool left = false;
  Eigen::Vector3d p;
  double beyond = 0;  // how far past the rim [mm]
  for (double x = 1; x < 30 && beyond < 1.0; x += 0.05) {
    p = mm(x, 1, -3);
    const ForceSample sample = testing::evaluate_static(*old_ir, p, {});
    if (sample.flags & kOutsidePatch) {
      left = true;
      beyond += 0.05;
    }
    ASSERT_TRUE(sample.force.allFinite());
    largest_jump = std::max(largest_jump, (sample.force - previous).norm());
    previous = sample.force;
  }
  ASSERT_TRUE(left) << "the slide should leave a one-triangle patch";
  // Held on the patch's rim: still continuous.
  EXPECT_LT(largest_jump, 0.01 * previous.norm());
  // The next IR is centred on the new triangle: its force is the exact one there.
  simulation.set_tool(0, p);
  simulation.step(0.01);
  const Eigen::Vector3d exact = simulation.force(0).force;
  EXPECT_LE(relative_error(
                exact, reference_forces(model, simulation, {p}, ContactModel::point_constraint)[0]),
            1e-9);
  std::printf(
      "  1 mm past a one-triangle patch: force held on the rim %.3f N, exact at the new triangle "
      "%.3f N "
      "(jump %.3f N when the next IR arrives)\n",
      previous.norm(), exact.norm(), (exact - previous).norm());
  EXPECT_LT((exact - previous).norm(), 0.25 * exact.norm());
}

TEST(IntermediateRepresentation, SphereToolsEqualTheFullSolve) {
  Rig& rig = shared_cube();
  const Model& model = *rig.model;
  const ElasticBody& body = single_elastic_body(model);
  const double radius = 4e-3;
  for (ContactModel contact_model :
       {ContactModel::node_translation, ContactModel::point_constraint}) {
    std::vector<ToolSpec> tools(2);
    for (ToolSpec& tool : tools) {
      tool.shape = ToolShape::sphere;
      tool.radius = radius;
    }
    Simulation simulation(single_elastic_body(model), model.obstacles, *rig.columns, tools,
                          unlimited_options(contact_model));
    // Centres outside the surface (1 mm above it) and inside (2 mm below): both press.
    const std::vector<Eigen::Vector3d> centres = {mm(-20, 5, 1), mm(25, -5, -2)};
    simulation.set_tool(0, centres[0]);
    simulation.set_tool(1, centres[1]);
    simulation.step(0);
    std::vector<PressedTool> pressed = {{centres[0], radius}, {centres[1], radius}};
    const HeldNodes held{simulation.condensation().boundary_nodes(),
                         simulation.boundary_displacement()};
    const auto reference =
        contact_reactions_reference(body, find_tool_contacts(body, pressed), held, contact_model);
    for (int user = 0; user < 2; ++user) {
      ASSERT_TRUE(reference[user].query.contact.has_value());
      EXPECT_NEAR(reference[user].query.contact->depth, user == 0 ? 3e-3 : 6e-3, 1e-12);
      EXPECT_LE(relative_error(simulation.force(user).force, reference[user].reaction), 1e-9)
          << "user " << user;
    }
  }
}

TEST(IntermediateRepresentation, NonFiniteToolsGiveZeroOrAreIgnored) {
  Rig& rig = shared_cube();
  const Model& model = *rig.model;
  Simulation simulation(single_elastic_body(model), model.obstacles, *rig.columns,
                        std::vector<ToolSpec>(2),
                        unlimited_options(ContactModel::node_translation));
  simulation.set_tool(0, mm(-20, 5, -4));
  simulation.set_tool(1, mm(25, -5, -3));
  simulation.step(0);
  const PreparedIR& prepared = *simulation.ir(0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const ForceSample own_nan = testing::evaluate_static(prepared, Eigen::Vector3d(nan, 0, 0), {});
  EXPECT_EQ(own_nan.force, Eigen::Vector3d::Zero());
  EXPECT_TRUE(own_nan.flags & kNonFinite);
  // An unknown remote leaves its nodes unloaded: the force of the own tool alone.
  const Eigen::Vector3d unknown(nan, nan, nan);
  const ForceSample alone =
      testing::evaluate_static(prepared, mm(-20, 5, -4), std::span(&unknown, 1));
  EXPECT_LE(relative_error(alone.force, reference_forces(model, simulation, {mm(-20, 5, -4)},
                                                         ContactModel::node_translation)[0]),
            1e-9);
}

TEST(IntermediateRepresentation, PrepareRejectsMalformedIrs) {
  Rig& rig = shared_cube();
  Simulation simulation(rig.body, rig.model->obstacles, *rig.columns, std::vector<ToolSpec>(1),
                        unlimited_options(ContactModel::node_translation));
  simulation.set_tool(0, mm(0, 0, -2));
  simulation.step(0);
  const IntermediateRepresentation good = simulation.ir(0)->ir;
  IntermediateRepresentation bad = good;
  condensed_fem(bad).m_tilde(0, 0) = std::numeric_limits<double>::infinity();
  EXPECT_THROW(prepare_ir(bad), Error);
  bad = good;
  condensed_fem(bad).m_tilde.conservativeResize(condensed_fem(bad).m_tilde.rows() - 1,
                                                Eigen::NoChange);
  EXPECT_THROW(prepare_ir(bad), Error);
  bad = good;
  condensed_fem(bad).m_tilde.leftCols(condensed_fem(bad).m_tilde.rows()) *=
      -1;  // not positive definite
  EXPECT_THROW(prepare_ir(bad), Error);
  bad = good;
  condensed_fem(bad).patch[0].nodes[1] = condensed_fem(bad).node_count() + 5;
  EXPECT_THROW(prepare_ir(bad), Error);
  bad = good;  // a lying server: M_CC not symmetric (its symmetric part is still definite)
  Eigen::MatrixXd& m_tilde = condensed_fem(bad).m_tilde;
  m_tilde(0, 1) += 1e-3 * m_tilde.leftCols(m_tilde.rows()).cwiseAbs().maxCoeff();
  EXPECT_THROW(prepare_ir(bad), Error);
  EXPECT_NO_THROW(prepare_ir(good));
}

}  // namespace
}  // namespace cohaptic
