// The sphere contact model: its unilateral solve against an enumeration of every active
// set, its geometry against hand-worked cases, and the intermediate representation's force
// and contact set against the full sparse FEM solve of the same unilateral problem (one and
// two users, held boundary nodes, sliding), which is itself checked against the
// complementarity conditions on an independently solved displacement field.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <random>

#include "common/contact/obstacle_constraints.h"
#include "common/contact/sphere_contact.h"
#include "common/contact/unilateral_contact_solve.h"
#include "common/contact/working_set_contact_solve.h"
#include "common/fem/static_solve.h"
#include "common/ir/evaluate_sphere_contact.h"
#include "common/model/sphere_contact_reference.h"
#include "common/scene/load_scene.h"
#include "common/sim/simulation.h"
#include "common/util/error.h"
#include "proto/wire/ir_convert.h"
#include "support/brain_scene.h"
#include "support/cube_scene.h"
#include "support/expect_refused.h"
#include "support/measures.h"
#include "support/test_meshes.h"
#include "support/unlimited_options.h"

namespace cohaptic {
namespace {

using testing::expect_refused;
using testing::mm;
using testing::relative_error;
using testing::unlimited_options;

// ---------------------------------------------------------------------------------------
// The unilateral solve.

struct Lcp {
  Eigen::MatrixXd a;
  Eigen::VectorXd q;
};

Lcp random_lcp(std::mt19937& random, int m) {
  std::normal_distribution<double> normal(0, 1);
  Eigen::MatrixXd g(m, m);
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j) g(i, j) = normal(random);
  Lcp lcp;
  lcp.a = g * g.transpose() + 0.05 * m * Eigen::MatrixXd::Identity(m, m);
  lcp.q = Eigen::VectorXd(m);
  for (int i = 0; i < m; ++i) lcp.q[i] = normal(random);
  return lcp;
}

// Every set S in turn: lambda_S = -A_SS^-1 q_S; the one that satisfies all conditions.
std::vector<Eigen::VectorXd> enumerate_solutions(const Lcp& lcp) {
  const auto m = static_cast<int>(lcp.q.size());
  std::vector<Eigen::VectorXd> solutions;
  for (int mask = 0; mask < (1 << m); ++mask) {
    std::vector<int> set;
    for (int i = 0; i < m; ++i)
      if (mask & (1 << i)) set.push_back(i);
    const auto k = static_cast<Eigen::Index>(set.size());
    Eigen::MatrixXd a_ss(k, k);
    Eigen::VectorXd q_s(k);
    for (Eigen::Index i = 0; i < k; ++i) {
      q_s[i] = lcp.q[set[i]];
      for (Eigen::Index j = 0; j < k; ++j) a_ss(i, j) = lcp.a(set[i], set[j]);
    }
    Eigen::VectorXd lambda = Eigen::VectorXd::Zero(m);
    if (k > 0) {
      const Eigen::VectorXd x = a_ss.ldlt().solve(-q_s);
      for (Eigen::Index i = 0; i < k; ++i) lambda[set[i]] = x[i];
    }
    const Eigen::VectorXd w = lcp.a * lambda + lcp.q;
    bool ok = true;
    for (int i = 0; i < m; ++i) ok &= (mask & (1 << i)) ? lambda[i] >= 0 : w[i] >= 0;
    if (ok) solutions.push_back(lambda);
  }
  return solutions;
}

TEST(UnilateralContactSolve, EqualsTheOneActiveSetOfAnEnumerationFromAnyWarmStart) {
  std::mt19937 random(7);
  int checked = 0, most_trials = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const int m = 1 + trial % 10;
    const Lcp lcp = random_lcp(random, m);
    const std::vector<Eigen::VectorXd> expected = enumerate_solutions(lcp);
    ASSERT_EQ(expected.size(), 1u) << "a positive definite LCP has one solution";
    Eigen::VectorXd first;
    for (int start = 0; start < 4; ++start) {
      std::vector<std::uint8_t> active(static_cast<std::size_t>(m));
      for (auto& a : active)
        a = static_cast<std::uint8_t>(start == 0 ? 0 : start == 1 ? 1 : random() % 2);
      Eigen::VectorXd lambda(m);
      Eigen::MatrixXd factor(m, m);
      std::vector<int> order(static_cast<std::size_t>(m));
      const UnilateralSolveResult result = solve_unilateral_contact(
          lcp.a, lcp.q, active, lambda, factor, order, std::numeric_limits<double>::infinity());
      ASSERT_TRUE(result.solved);
      most_trials = std::max(most_trials, result.trials);
      EXPECT_LE((lambda - expected[0]).norm(), 1e-10 * (1 + expected[0].norm()))
          << "m " << m << " start " << start;
      for (int i = 0; i < m; ++i)
        EXPECT_EQ(active[static_cast<std::size_t>(i)] != 0, lambda[i] > 0 || (expected[0][i] > 0));
      // The answer depends on the final set only: bit-identical from every warm start.
      if (start == 0)
        first = lambda;
      else
        EXPECT_TRUE(lambda == first) << "m " << m << " start " << start;
      ++checked;
    }
  }
  std::printf(
      "  %d solves of LCPs with 1 to 10 unknowns, every one the enumeration's; at most %d sets "
      "factored\n",
      checked, most_trials);
}

TEST(UnilateralContactSolve, ReportsFailureBeyondItsBudgetAndForAnIndefiniteMatrix) {
  std::mt19937 random(3);
  const Lcp lcp = random_lcp(random, 30);
  std::vector<std::uint8_t> active(30, 0);
  Eigen::VectorXd lambda(30);
  Eigen::MatrixXd factor(30, 30);
  std::vector<int> order(30);
  EXPECT_FALSE(solve_unilateral_contact(lcp.a, lcp.q, active, lambda, factor, order, 10).solved);
  Lcp indefinite = lcp;
  indefinite.a(3, 3) = -1;
  std::fill(active.begin(), active.end(), 1);
  EXPECT_FALSE(
      solve_unilateral_contact(indefinite.a, indefinite.q, active, lambda, factor, order, 1e9)
          .solved);
}

TEST(UnilateralContactSolve, TheWorkingSetEqualsTheDenseSolveOverEveryCandidate) {
  std::mt19937 random(11);
  int grown = 0, checked = 0;
  for (int trial = 0; trial < 100; ++trial) {
    const int m = 20 + trial % 41;
    Lcp lcp = random_lcp(random, m);
    lcp.q.array() +=
        0.5;  // most candidates clear of the tool with no push, a few pushed in by the others
    std::vector<std::uint8_t> dense_active(static_cast<std::size_t>(m), 0);
    Eigen::VectorXd dense(m);
    Eigen::MatrixXd factor(m, m);
    std::vector<int> order(static_cast<std::size_t>(m));
    ASSERT_TRUE(solve_unilateral_contact(lcp.a, lcp.q, dense_active, dense, factor, order,
                                         std::numeric_limits<double>::infinity())
                    .solved);
    for (int start = 0; start < 2; ++start) {
      std::vector<std::uint8_t> active(static_cast<std::size_t>(m), 0),
          member_active(active.size()), in_set(active.size());
      if (start == 1)
        for (auto& a : active) a = static_cast<std::uint8_t>(random() % 4 == 0);
      std::vector<int> members(active.size()), member_order(active.size());
      WorkingSetScratch<Eigen::MatrixXd, Eigen::VectorXd> scratch{
          {}, {}, {}, {}, members, member_active, member_order, in_set};
      Eigen::VectorXd lambda(m);
      const auto entry = [&](int i, int j) {
        EXPECT_TRUE(in_set[static_cast<std::size_t>(j)]) << "a column outside the working set";
        return lcp.a(i, j);
      };
      const WorkingSetSolveResult result = solve_unilateral_over_candidates(
          lcp.q, entry, [](std::span<const int>) {}, m, active, lambda, scratch,
          std::numeric_limits<double>::infinity());
      ASSERT_TRUE(result.inner.solved);
      EXPECT_LE((lambda - dense).norm(), 1e-10 * (1 + dense.norm()))
          << "m " << m << " start " << start;
      for (int i = 0; i < m; ++i)
        EXPECT_EQ(active[static_cast<std::size_t>(i)] != 0,
                  dense_active[static_cast<std::size_t>(i)] != 0)
            << "m " << m;
      grown += result.passes > 1;
      ++checked;
      if (start == 0 && result.largest_set > 1) {  // too small a limit is refused, not answered
        std::vector<std::uint8_t> cold(active.size(), 0);
        EXPECT_TRUE(solve_unilateral_over_candidates(
                        lcp.q, entry, [](std::span<const int>) {}, result.largest_set - 1, cold,
                        lambda, scratch, std::numeric_limits<double>::infinity())
                        .set_too_large);
      }
    }
  }
  std::printf(
      "  %d solves over 20 to 60 candidates equal the dense solve; %d needed the set to grow\n",
      checked, grown);
  EXPECT_GT(grown, 10) << "no candidate outside the first set was ever carried in";
}

// ---------------------------------------------------------------------------------------
// The geometry.

TEST(SphereContact, TakesEveryNodeAlongItsOwnNormalFromTheSphereWithTheLeastGap) {
  const Eigen::Vector3d down(0, 0, -1);  // the inward normal of a surface facing +z
  const std::vector<SphereTool> one = {{Eigen::Vector3d(0, 0, 1), 2}};
  const auto held = sphere_constraint(Eigen::Vector3d(0, 0, 0), down, 0, one);
  ASSERT_TRUE(held.has_value());
  EXPECT_DOUBLE_EQ(held->gap, -1) << "inside: it must move down to the sphere's bottom";
  EXPECT_TRUE(held->normal.isApprox(down));
  const auto outside = sphere_constraint(Eigen::Vector3d(0, 0, -1.5), down, 0, one);
  ASSERT_TRUE(outside.has_value())
      << "outside the sphere: a candidate the deformation may carry in";
  EXPECT_DOUBLE_EQ(outside->gap, 0.5);
  EXPECT_EQ(sphere_constraint(Eigen::Vector3d(0, 0, -1), down, 0, one)->gap, 0) << "exactly on it";
  EXPECT_DOUBLE_EQ(sphere_constraint(Eigen::Vector3d(0, 0, 1), down, 0, one)->gap, -2)
      << "at the centre: a radius";
  // Off the axis the gap is measured along the node's normal, not towards the centre: the
  // sphere's bottom above (1.5, 0) is at z = 1 - sqrt(4 - 2.25).
  EXPECT_NEAR(sphere_constraint(Eigen::Vector3d(1.5, 0, 0), down, 0, one)->gap, 1 - std::sqrt(1.75),
              1e-15);
  EXPECT_FALSE(sphere_constraint(Eigen::Vector3d(3, 0, 0), down, 0, one).has_value())
      << "its line misses the sphere";
  EXPECT_FALSE(sphere_constraint(Eigen::Vector3d(0, 0, 5), down, 0, one).has_value())
      << "the sphere lies wholly ahead of it, inside the body";
  EXPECT_DOUBLE_EQ(sphere_constraint(Eigen::Vector3d(0, 0, 5), -down, 0, one)->gap, 2)
      << "a surface facing -z above the sphere: clear by 2";
  EXPECT_FALSE(sphere_constraint(Eigen::Vector3d(0, 0, 0), down, 0b100, one).has_value())
      << "normal along its fixed axis";
  const Eigen::Vector3d tilted(-0.6, 0, -0.8);
  EXPECT_TRUE(sphere_constraint(Eigen::Vector3d(0, 0, 0), tilted, 0b100, one).has_value())
      << "a free part of the normal";
  EXPECT_FALSE(
      sphere_constraint(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d::Zero(), 0, one).has_value())
      << "no touchable triangle: no normal";
  const std::vector<SphereTool> two = {{Eigen::Vector3d(0, 0, 1), 2},
                                       {Eigen::Vector3d(0.5, 0, 0.5), 2},
                                       {Eigen::Vector3d::Constant(std::nan("")), 5}};
  const auto deepest = sphere_constraint(Eigen::Vector3d(0, 0, 0), down, 0, two);
  ASSERT_TRUE(deepest.has_value());
  EXPECT_EQ(deepest->tool, 1);
  EXPECT_NEAR(deepest->gap, 0.5 - std::sqrt(3.75), 1e-15);
  const auto nearer = sphere_constraint(Eigen::Vector3d(0, 0, -2), down, 0, two);  // outside both
  ASSERT_TRUE(nearer.has_value());
  EXPECT_EQ(nearer->tool, 1);
  EXPECT_NEAR(nearer->gap, 2.5 - std::sqrt(3.75), 1e-15);
}

TEST(SphereContact, ANodesNormalIsItsTouchableTrianglesOnly) {
  const TetMesh mesh = testing::distorted_box_mesh(1.0, 3, 0.0, 1);
  const BoundarySurface surface = extract_boundary_surface(mesh);
  std::vector<int> top;  // the face z = 1 alone is touchable
  for (int t = 0; t < surface.triangle_count(); ++t) {
    bool on_top = true;
    for (int node : surface.triangles[static_cast<std::size_t>(t)])
      on_top &= mesh.nodes(2, node) == 1.0;
    if (on_top) top.push_back(t);
  }
  const Eigen::Matrix3Xd normals = contact_normals(mesh, surface, top);
  int edge_nodes = 0;
  for (int node = 0; node < mesh.node_count(); ++node) {
    if (mesh.nodes(2, node) != 1.0) {
      EXPECT_EQ(normals.col(node).norm(), 0) << "node " << node << " has no touchable triangle";
      continue;
    }
    // On the top's rim too, where the whole surface's normal leans over the side.
    EXPECT_LE((normals.col(node) - Eigen::Vector3d(0, 0, -1)).norm(), 1e-15) << "node " << node;
    edge_nodes += mesh.nodes(0, node) == 0.0 || mesh.nodes(0, node) == 1.0;
  }
  EXPECT_GT(edge_nodes, 0);
}

// ---------------------------------------------------------------------------------------
// The intermediate representation against the full sparse solve.

constexpr double kSphereRadius =
    30e-3;  // on the 11.8 mm cube mesh a 4 mm press holds several nodes

testing::CubeSceneOptions sphere_cube() {
  testing::CubeSceneOptions options;
  options.tools = "[{name: A, shape: sphere, radius: 30}, {name: B, shape: sphere, radius: 30}]";
  return options;
}

testing::CubeRig& shared_rig() {
  static testing::CubeRig rig(sphere_cube());
  return rig;
}

// Mesh node tags of the IR's nodes in contact at the evaluation that left `state`.
std::vector<std::int64_t> ir_contact_tags(const PreparedIR& prepared,
                                          const EvaluationState& state) {
  std::vector<std::int64_t> tags;
  for (int i = 0; i < condensed_fem(prepared.ir).row_node_count; ++i)
    if (std::get<FemEvaluation>(state.body).sphere->solve.push(i) > 0)
      tags.push_back(condensed_fem(prepared.ir).node_ids[static_cast<std::size_t>(i)]);
  std::sort(tags.begin(), tags.end());
  return tags;
}

std::vector<std::int64_t> tags_of(const ElasticBody& body, const std::vector<int>& nodes) {
  std::vector<std::int64_t> tags;
  for (int node : nodes) tags.push_back(body.mesh.node_tags[static_cast<std::size_t>(node)]);
  std::sort(tags.begin(), tags.end());
  return tags;
}

HeldNodes held_nodes(const Simulation& simulation) {
  return {simulation.condensation().boundary_nodes(), simulation.boundary_displacement()};
}

// The user's IR evaluated at the tools' positions against the reference, force and contact
// set; returns the relative force error (and counts the nodes).
struct SphereComparison {
  double worst = 0;
  int checked = 0, contact_nodes = 0, released_nodes = 0;
};

void compare(const ElasticBody& body, const Simulation& simulation,
             const std::vector<Eigen::Vector3d>& tools, int user, SphereComparison& comparison,
             double radius = kSphereRadius, const std::vector<SphereConstraint>& obstacles = {}) {
  const PreparedIR& prepared = *simulation.ir(user);
  std::vector<Eigen::Vector3d> remotes;
  for (int r = 0; r < remote_count(prepared.ir); ++r)
    remotes.push_back(tools[static_cast<std::size_t>(remote_user(prepared.ir, r))]);
  EvaluationState state = make_evaluation_state(prepared);
  std::get<FemEvaluation>(state.body).sphere->work_budget = std::numeric_limits<double>::infinity();
  const ForceSample sample =
      evaluate_force(prepared, state, tools[static_cast<std::size_t>(user)], remotes, 1e-3);
  std::vector<PressedTool> pressed;
  for (const Eigen::Vector3d& p : tools) pressed.push_back({p, radius});
  const SphereContactSolution reference =
      sphere_reactions_reference(body, pressed, held_nodes(simulation), nullptr, obstacles);
  const Eigen::Vector3d expected = reference.reactions[static_cast<std::size_t>(user)];
  ASSERT_FALSE(sample.flags & (kOutsidePatch | kContactUnresolved | kNonFinite));
  if (expected.norm() == 0) {
    EXPECT_EQ(sample.force.norm(), 0);
    return;
  }
  const double error = relative_error(sample.force, expected);
  EXPECT_LE(error, 1e-9) << "user " << user << " at "
                         << tools[static_cast<std::size_t>(user)].transpose() * 1e3 << " mm";
  comparison.worst = std::max(comparison.worst, error);
  // The node set: every node in contact in the reference is one in the IR's last solve.
  EXPECT_EQ(ir_contact_tags(prepared, state), tags_of(body, reference.contact_nodes()));
  comparison.contact_nodes += static_cast<int>(reference.contact_nodes().size());
  for (std::size_t i = 0; i < reference.candidates.size(); ++i)  // held at rest, yet released
    comparison.released_nodes +=
        reference.constraints[i].gap < 0 && !(reference.pushes[static_cast<Eigen::Index>(i)] > 0);
  ++comparison.checked;
}

TEST(SphereContact, OneSphereSlidingEqualsTheFullSparseSolveInForceAndNodeSet) {
  testing::CubeRig& rig = shared_rig();
  const ElasticBody& body = rig.body;
  Simulation simulation(body, rig.model->obstacles, *rig.columns,
                        std::vector<ToolSpec>(1, rig.model->scene.tools[0]),
                        unlimited_options(ContactModel::sphere));
  SphereComparison comparison;
  // Press the centre 4 mm below touching, then slide 20 mm across several nodes.
  for (int k = 0; k <= 24; ++k) {
    const double depth = std::min(k, 8) * 0.5;  // mm
    const double slide = std::max(0, k - 8) * 1.25;
    const Eigen::Vector3d centre = mm(-7 + slide, 3, 30 - depth);
    simulation.set_tool(0, centre);
    simulation.step(k * 1e-3);
    ASSERT_TRUE(simulation.ir(0));
    compare(body, simulation, {centre}, 0, comparison);
  }
  std::printf(
      "  %d positions: worst relative force error %.2e; %d node contacts, %d held nodes released\n",
      comparison.checked, comparison.worst, comparison.contact_nodes, comparison.released_nodes);
  EXPECT_GT(comparison.checked, 10);
  EXPECT_GT(comparison.released_nodes, 0) << "the unilateral release never happened";
}

TEST(SphereContact, BetweenIrUpdatesTheClientFollowsTheSphereExactly) {
  testing::CubeRig& rig = shared_rig();
  const ElasticBody& body = rig.body;
  Simulation simulation(body, rig.model->obstacles, *rig.columns,
                        std::vector<ToolSpec>(1, rig.model->scene.tools[0]),
                        unlimited_options(ContactModel::sphere, 0, 2));
  simulation.set_tool(0, mm(0, 0, 27));
  simulation.step(0);
  SphereComparison comparison;
  // The IR stays the one built at 27 mm; the tool goes 2 mm deeper and 4 mm sideways.
  for (int k = 0; k <= 10; ++k)
    compare(body, simulation, {mm(0.4 * k, 0, 27 - 0.2 * k)}, 0, comparison);
  std::printf("  one IR, %d positions: worst relative force error %.2e\n", comparison.checked,
              comparison.worst);
  EXPECT_EQ(comparison.checked, 11);
}

TEST(SphereContact, TwoSpheresAndHeldNodesEqualTheFullSparseSolve) {
  testing::CubeRig& rig = shared_rig();
  const ElasticBody& body = rig.body;
  for (int step_delay_nodes : {0, 150}) {
    Simulation simulation(body, rig.model->obstacles, *rig.columns, rig.model->scene.tools,
                          unlimited_options(ContactModel::sphere, step_delay_nodes));
    SphereComparison comparison;
    for (int k = 0; k <= 12; ++k) {
      const std::vector<Eigen::Vector3d> tools = {mm(-22 + k, 4, 27 - 0.25 * std::min(k, 8)),
                                                  mm(21, -6 + 0.5 * k, 26.5)};
      simulation.set_tool(0, tools[0]);
      simulation.set_tool(1, tools[1]);
      simulation.step(k * 1e-3);
      for (int user = 0; user < 2; ++user) compare(body, simulation, tools, user, comparison);
    }
    std::printf("  two spheres, %d held nodes: %d comparisons, worst relative force error %.2e\n",
                step_delay_nodes, comparison.checked, comparison.worst);
    EXPECT_EQ(comparison.checked, 26);
  }
}

// One or two spheres pressed 0.2-6 mm (cube) or 0.2-4 mm (brain) into the surface at random
// places, each from rest in one step, as `cohaptic-lab probe` does: every IR's force and
// contact set equal the full sparse solve of the same unilateral problem. On the brain the
// skull holds nodes, sliding (the obstacles' constraints), and the tips are 7 mm spheres on
// 9 mm elements.
void press_at_random_places(const ElasticBody& body, const Model& model, ComplianceColumns& columns,
                            double radius, double max_depth, int positions, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_int_distribution<std::size_t> any_node(0, body.touchable_nodes.size() - 1);
  std::uniform_real_distribution<double> depth(0.2e-3, max_depth);
  SphereComparison comparison;
  int two_spheres = 0;
  const std::vector<SphereConstraint> obstacles =
      model.obstacles.empty()
          ? std::vector<SphereConstraint>{}
          : obstacle_constraints(body.mesh, body.surface, body.dofs, model.obstacles);
  for (int k = 0; k < positions; ++k) {
    // A sphere of `radius` whose surface reaches `depth` below a touchable node, along its normal.
    const auto pressed_at = [&] {
      const int node = body.touchable_nodes[any_node(random)];
      return Eigen::Vector3d(body.mesh.nodes.col(node) +
                             body.normals.vertex.col(node) * (radius - depth(random)));
    };
    std::vector<Eigen::Vector3d> tools = {pressed_at()};
    if (k % 2 == 1) tools.push_back(pressed_at());
    two_spheres += tools.size() == 2;
    Simulation simulation(body, model.obstacles, columns,
                          std::vector<ToolSpec>(tools.size(), model.scene.tools[0]),
                          unlimited_options(ContactModel::sphere));
    for (std::size_t user = 0; user < tools.size(); ++user)
      simulation.set_tool(static_cast<int>(user), tools[user]);
    const StepReport report = simulation.step(0);
    EXPECT_EQ(report.sphere_nodes_outside_patches, 0);
    for (std::size_t user = 0; user < tools.size(); ++user) {
      SCOPED_TRACE("position " + std::to_string(k) + ", user " + std::to_string(user));
      ASSERT_TRUE(simulation.ir(static_cast<int>(user)));
      compare(body, simulation, tools, static_cast<int>(user), comparison, radius, obstacles);
    }
  }
  std::printf(
      "  %d IRs (%d positions with two spheres): worst relative force error %.2e; %d node "
      "contacts, %d held "
      "nodes released\n",
      comparison.checked, two_spheres, comparison.worst, comparison.contact_nodes,
      comparison.released_nodes);
  EXPECT_GT(comparison.contact_nodes, positions)
      << "the spheres pressed too little to test anything";
}

TEST(SphereContact, AtRandomPlacesOnTheCubeEqualsTheFullSparseSolve) {
  testing::CubeRig& rig = shared_rig();
  press_at_random_places(rig.body, *rig.model, *rig.columns, kSphereRadius, 6e-3, 24, 5);
}

TEST(SphereContact, AtRandomPlacesOnTheBrainEqualsTheFullSparseSolve) {
  const Model model = build_model(testing::brain_scene(testing::kCoarseBrainMesh));
  const ElasticBody& body = single_elastic_body(model);
  ComplianceColumns columns(body.free_factor, body.dofs, body.surface.nodes);
  press_at_random_places(body, model, columns, model.scene.tools[0].radius, 4e-3, 16, 9);
}

TEST(SphereContact, TheReferenceMeetsTheContactConditionsOnAnIndependentSolve) {
  testing::CubeRig& rig = shared_rig();
  const ElasticBody& body = rig.body;
  const std::vector<PressedTool> tools = {
      {mm(-6, 2, 25), kSphereRadius}};  // 7 passed nodes, 4 touching
  const SphereContactSolution solution = sphere_reactions_reference(body, tools);
  ASSERT_GT(solution.contact_nodes().size(), 3u);
  // Apply the pushes as loads and solve the whole body once more, with no constraint.
  Eigen::VectorXd loads = Eigen::VectorXd::Zero(3 * body.mesh.node_count());
  for (std::size_t i = 0; i < solution.candidates.size(); ++i)
    loads.segment<3>(3 * solution.candidates[i]) +=
        solution.pushes[static_cast<Eigen::Index>(i)] * solution.constraints[i].normal;
  const StaticSolution free = solve_static(body.stiffness, body.dofs, {}, loads);
  double scale = 0;
  for (const SphereConstraint& c : solution.constraints) scale = std::max(scale, -c.gap);
  int touching = 0, released = 0;
  for (std::size_t i = 0; i < solution.candidates.size(); ++i) {
    const SphereConstraint& c = solution.constraints[i];
    const double clearance =
        c.normal.dot(free.displacement.segment<3>(3 * solution.candidates[i])) + c.gap;
    const double push = solution.pushes[static_cast<Eigen::Index>(i)];
    EXPECT_GE(push, 0);
    if (push > 0) {
      EXPECT_NEAR(clearance, 0, 1e-9 * scale) << "a pushed node is on the sphere";
      ++touching;
    } else {
      EXPECT_GE(clearance, -1e-9 * scale) << "a free candidate is outside the sphere";
      released += c.gap < 0;  // held at rest, yet released
    }
  }
  // The tool's force is what the body's supports take: the pushes sum to minus the reaction.
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int node = 0; node < body.mesh.node_count(); ++node)
    if (body.dofs.fixed_axes[static_cast<std::size_t>(node)] != 0)
      sum += free.reaction.segment<3>(3 * node);
  EXPECT_LE((sum - solution.reactions[0]).norm(), 1e-9 * solution.reactions[0].norm());
  std::printf("  %d nodes touch the sphere, %d passed nodes released; |F| = %.4f N\n", touching,
              released, solution.reactions[0].norm());
  EXPECT_GT(released, 0);
}

// ---------------------------------------------------------------------------------------
// The sphere IR on the wire and its checks.

// A sphere IR of the first of two spheres with 150 step-delay nodes held (B).
IntermediateRepresentation two_sphere_ir() {
  testing::CubeRig& rig = shared_rig();
  Simulation simulation(rig.body, rig.model->obstacles, *rig.columns, rig.model->scene.tools,
                        unlimited_options(ContactModel::sphere, 150));
  simulation.set_tool(0, mm(-6, 2, 26));
  simulation.set_tool(1, mm(20, -4, 27));
  simulation.step(0);
  return simulation.ir(0)->ir;
}

TEST(SphereIr, TravelsBitForBitWithItsUpperTriangleAndFloatRoundsW) {
  const IntermediateRepresentation ir = two_sphere_ir();
  const CondensedFemIr& fem = condensed_fem(ir);
  ASSERT_TRUE(fem.sphere);
  const SphereContactIr& sphere = *fem.sphere;
  ASSERT_FALSE(sphere.contacts.empty());
  ASSERT_EQ(sphere.held_node_ids.size(), 150u);
  ASSERT_EQ(fem.m_tilde.size(), 0);
  const auto n = static_cast<std::size_t>(fem.row_node_count);
  const wire::IntermediateRepresentation w = wire::to_wire(ir);
  EXPECT_EQ(static_cast<std::size_t>(w.fem().sphere().normal_compliance_f64_size()),
            n * (n + 1) / 2);
  const IntermediateRepresentation back = wire::from_wire(w);
  const SphereContactIr& received = *condensed_fem(back).sphere;
  EXPECT_TRUE(received.normal_compliance == sphere.normal_compliance);
  EXPECT_TRUE(received.normals == sphere.normals);
  EXPECT_TRUE(received.free_clearance == sphere.free_clearance);
  EXPECT_EQ(received.contacts, sphere.contacts);
  EXPECT_EQ(received.held_node_ids, sphere.held_node_ids);
  const PreparedIR a = prepare_ir(ir), b = prepare_ir(back);
  EvaluationState state_a = make_evaluation_state(a), state_b = make_evaluation_state(b);
  const std::vector<Eigen::Vector3d> remote = {mm(20, -4, 27)};
  EXPECT_EQ(evaluate_force(a, state_a, mm(-6, 2, 26), remote, 1e-3).force,
            evaluate_force(b, state_b, mm(-6, 2, 26), remote, 1e-3).force);

  IntermediateRepresentation single = ir;
  condensed_fem(single).precision = IrPrecision::f32;
  const IntermediateRepresentation rounded = wire::from_wire(wire::to_wire(single));
  EXPECT_EQ(condensed_fem(rounded).precision, IrPrecision::f32);
  EXPECT_TRUE(condensed_fem(rounded).sphere->normal_compliance ==
              sphere.normal_compliance.cast<float>().cast<double>());
}

TEST(SphereIr, EveryInconsistencyIsRefusedNamingIt) {
  const IntermediateRepresentation ir = two_sphere_ir();
  const wire::IntermediateRepresentation valid = wire::to_wire(ir);
  ASSERT_NO_THROW(prepare_ir(wire::from_wire(valid)));
  wire::IntermediateRepresentation w = valid;
  w.mutable_fem()->mutable_sphere()->mutable_normal_compliance_f64()->RemoveLast();
  expect_refused(w, "sphere.normal_compliance has");
  w = valid;
  w.mutable_fem()->mutable_sphere()->set_normal_compliance_f64(3, std::nan(""));
  expect_refused(w, "sphere.normal_compliance_f64[3] is not finite");
  w = valid;
  w.mutable_fem()->mutable_sphere()->add_normal_compliance_f32(1.0f);
  expect_refused(w, "in both f64 and f32");
  w = valid;
  w.mutable_fem()->mutable_sphere()->set_contacts(
      0, static_cast<std::uint32_t>(w.fem().row_node_count()));
  expect_refused(w, "sphere.contacts names row node");
  w = valid;
  w.mutable_fem()->mutable_sphere()->mutable_free_clearance()->RemoveLast();
  expect_refused(w, "sphere.free_clearance has");
  w = valid;
  w.set_format_version(5);
  expect_refused(w, "format version 5 carries a sphere body as M~");
  w = valid;
  w.mutable_fem()->clear_sphere();
  expect_refused(w, "a sphere body without its normal compliance");
  w = valid;
  w.mutable_fem()->set_contact_model(wire::CondensedFem::TRANSLATION);
  expect_refused(w, "a sphere contact part under another contact model");
  w = valid;
  w.mutable_fem()->set_m_rows(3);
  expect_refused(w, "carries its row nodes and its normal compliance only");

  const auto tampered = [&](const std::function<void(SphereContactIr&)>& change) {
    IntermediateRepresentation copy = ir;
    change(*condensed_fem(copy).sphere);
    return copy;
  };
  const int contact = condensed_fem(ir).sphere->contacts.front();
  expect_refused(tampered([&](SphereContactIr& s) { s.normals.col(contact) *= 0.5; }),
                 "normal has length");
  expect_refused(tampered([&](SphereContactIr& s) { s.normal_compliance(contact, contact) = 0; }),
                 "not positive");
  expect_refused(tampered([&](SphereContactIr& s) {
                   s.normal_compliance(contact, contact == 0 ? 1 : 0) *= 2;
                 }),
                 "W is not symmetric");
  expect_refused(tampered([&](SphereContactIr& s) { s.contacts.push_back(s.contacts.front()); }),
                 "in ascending order");
  expect_refused(tampered([&](SphereContactIr& s) {
                   // Two contacts coupled more than their own compliances allow: W over them
                   // indefinite.
                   ASSERT_GE(s.contacts.size(), 2u);
                   const int a = s.contacts[0], b = s.contacts[1];
                   s.normal_compliance(a, b) = s.normal_compliance(b, a) =
                       2 * std::sqrt(s.normal_compliance(a, a) * s.normal_compliance(b, b));
                 }),
                 "is not positive definite");
}

TEST(SphereContact, IsTheSceneDefaultForSphereToolsAndNeedsThem) {
  const Scene spheres = parse_scene(testing::cube_scene_yaml(sphere_cube()), "cube.yaml");
  EXPECT_EQ(spheres.haptic.contact_model, ContactModel::sphere);
  const Scene points = parse_scene(testing::cube_scene_yaml(), "cube.yaml");
  EXPECT_EQ(points.haptic.contact_model, ContactModel::node_translation);
  std::string text = testing::cube_scene_yaml();
  text.replace(text.find("haptic: {"), 9, "haptic: {contact_model: sphere, ");
  try {
    parse_scene(text, "cube.yaml");
    FAIL() << "a point tool with the sphere model was accepted";
  } catch (const SceneError& error) {
    EXPECT_NE(std::string(error.what()).find("tool 'A' is a point"), std::string::npos)
        << error.what();
    EXPECT_NE(std::string(error.what()).find("haptic.contact_model"), std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace cohaptic
