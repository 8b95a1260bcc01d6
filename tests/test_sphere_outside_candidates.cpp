// Nodes that the tissue carries into a sphere. The sphere model's
// unilateral problem is posed over every touchable surface node, not only over those whose
// rest position lies inside a sphere: a node outside at rest (gap g0 > 0) that the body's
// deformation carries in (g0 + n.u < 0, linearised) must be held like any other.
//
// A column fixed at its foot has two 10 mm spheres near its top: A presses one side, B
// stands 0.3 mm off the opposite side and holds no node at rest. A bends the column into
// B, so B pushes back. The expected answer is this file's own full sparse solve of the
// linearised unilateral problem, every touchable free node paired with every sphere within
// one radius of it (nothing shared with the sphere model's candidate choice, its IR or its
// reference), checked against the contact conditions on one more independent solve. The
// IR of each user and SphereContactReference must equal it, force and contact set.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>

#include "common/contact/unilateral_contact_solve.h"
#include "common/fem/static_solve.h"
#include "common/ir/evaluate_force.h"
#include "common/model/sphere_contact_reference.h"
#include "common/sim/simulation.h"
#include "support/cube_scene.h"
#include "support/measures.h"
#include "support/unlimited_options.h"

namespace cohaptic {
namespace {

using testing::mm;
using testing::relative_error;

constexpr double kColumnSphereRadius = 10e-3;  // both spheres [m]
constexpr double kColumnStandoff = 0.3e-3;     // B's clearance from its face at rest [m]

// 20 x 20 x 100 mm, 2.5 mm cells, foot fixed, touchable on its -x and +x faces.
const std::string kColumnScene = R"(
units: mm
objects:
  - name: column
    mesh: {box: {min: [-10, -10, -100], size: [20, 20, 100], divisions: [8, 8, 40]}}
    material: {youngs_modulus: 1.0e6, poisson_ratio: 0.4}
    fixed: [{plane: {point: [0, 0, -100], normal: [0, 0, 1]}}]
    touchable: [{plane: {point: [-10, 0, 0], normal: [-1, 0, 0]}}, {plane: {point: [10, 0, 0], normal: [1, 0, 0]}}]
    compliance: {precompute: on_demand, disk_cache: false}
tools: [{name: A, shape: sphere, radius: 10}, {name: B, shape: sphere, radius: 10}]
haptic: {force_limit: 1000}
)";

// The linearised unilateral problem over (node, sphere) pairs, solved on the whole body.
struct ColumnPairProblem {
  std::vector<int> node, tool;
  std::vector<Eigen::Vector3d> normal;  // unit, the node's face's inward normal
  Eigen::VectorXd gap;                  // along it to the sphere's far side [m], either sign
  Eigen::VectorXd push;                 // lambda [N]
  std::vector<Eigen::Vector3d> force;   // on each sphere [N]
  std::vector<int> contact_nodes() const {
    std::vector<int> nodes;
    for (std::size_t p = 0; p < node.size(); ++p)
      if (push[static_cast<Eigen::Index>(p)] > 0) nodes.push_back(node[p]);
    std::sort(nodes.begin(), nodes.end());
    nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
    return nodes;
  }
};

// The whole body's compliance between every free touchable node's dofs (nothing held but
// the foot), from one multi-right-hand-side CHOLMOD solve.
struct ColumnTouchableCompliance {
  std::vector<int> nodes;      // free touchable nodes
  std::vector<int> first_row;  // per volume node: its first row in `block`, or -1
  Eigen::MatrixXd block;       // 3 rows and 3 columns per node [m/N]
};

ColumnTouchableCompliance column_touchable_compliance(const ElasticBody& body) {
  ColumnTouchableCompliance c;
  c.first_row.assign(static_cast<std::size_t>(body.mesh.node_count()), -1);
  std::vector<int> dofs;
  for (int node : body.touchable_nodes) {
    if (body.dofs.fixed_axes[static_cast<std::size_t>(node)] == kAllAxes) continue;
    c.first_row[static_cast<std::size_t>(node)] = static_cast<int>(dofs.size());
    c.nodes.push_back(node);
    for (int axis = 0; axis < 3; ++axis) dofs.push_back(3 * node + axis);
  }
  c.block = ConstrainedStaticSolver(body.stiffness, body.dofs, {}).compliance_block(dofs, dofs);
  return c;
}

ColumnPairProblem solve_every_column_pair(const ElasticBody& body,
                                          const ColumnTouchableCompliance& c,
                                          const std::vector<Eigen::Vector3d>& centres) {
  ColumnPairProblem problem;
  std::vector<double> gaps;
  for (int node : c.nodes) {
    const Eigen::Vector3d x = body.mesh.nodes.col(node);
    const Eigen::Vector3d inward(x.x() < 0 ? 1 : -1, 0, 0);  // the -x face's, or the +x face's
    for (int t = 0; t < static_cast<int>(centres.size()); ++t) {
      // x + s n on the sphere: s = -b -+ sqrt(b^2 - c); the node must reach the far crossing.
      const Eigen::Vector3d offset = x - centres[static_cast<std::size_t>(t)];
      const double b = inward.dot(offset),
                   c2 = offset.squaredNorm() - kColumnSphereRadius * kColumnSphereRadius;
      if (b * b - c2 < 0 || -b - std::sqrt(b * b - c2) > 0)
        continue;  // missed, or the sphere is ahead
      const double gap = b - std::sqrt(b * b - c2);
      if (gap >= kColumnSphereRadius) continue;  // far beyond anything the press can carry in
      problem.node.push_back(node);
      problem.tool.push_back(t);
      problem.normal.push_back(inward);
      gaps.push_back(gap);
    }
  }
  const auto m = static_cast<Eigen::Index>(gaps.size());
  problem.gap = Eigen::Map<const Eigen::VectorXd>(gaps.data(), m);
  Eigen::MatrixXd a(m, m);
  for (Eigen::Index p = 0; p < m; ++p)
    for (Eigen::Index q = 0; q < m; ++q)
      a(p, q) = problem.normal[static_cast<std::size_t>(p)].dot(
          c.block.block<3, 3>(
              c.first_row[static_cast<std::size_t>(problem.node[static_cast<std::size_t>(p)])],
              c.first_row[static_cast<std::size_t>(problem.node[static_cast<std::size_t>(q)])]) *
          problem.normal[static_cast<std::size_t>(q)]);
  a = 0.5 * (a + a.transpose()).eval();
  std::vector<std::uint8_t> active(static_cast<std::size_t>(m), 0);
  problem.push = Eigen::VectorXd::Zero(m);
  Eigen::MatrixXd factor(m, m);
  std::vector<int> order(static_cast<std::size_t>(m));
  // Nothing is held, so q is the rest gap itself (no free displacement).
  if (!solve_unilateral_contact(a, problem.gap, active, problem.push, factor, order,
                                std::numeric_limits<double>::infinity())
           .solved)
    throw std::runtime_error("the pairs' normal compliance is not positive definite");
  problem.force.assign(centres.size(), Eigen::Vector3d::Zero());
  for (Eigen::Index p = 0; p < m; ++p)
    problem.force[static_cast<std::size_t>(problem.tool[static_cast<std::size_t>(p)])] -=
        problem.push[p] * problem.normal[static_cast<std::size_t>(p)];
  return problem;
}

// The pushes as loads on the free body, solved once more: no pair penetrates, pushed pairs
// touch, pushes are non-negative. This holds for the unique solution only.
void expect_column_contact_conditions(const ElasticBody& body, const ColumnPairProblem& problem) {
  Eigen::VectorXd loads = Eigen::VectorXd::Zero(3 * body.mesh.node_count());
  for (std::size_t p = 0; p < problem.node.size(); ++p)
    loads.segment<3>(3 * problem.node[p]) +=
        problem.push[static_cast<Eigen::Index>(p)] * problem.normal[p];
  const Eigen::VectorXd u = solve_static(body.stiffness, body.dofs, {}, loads).displacement;
  constexpr double kTolerance = 1e-12;  // [m], against millimetre gaps and displacements
  for (std::size_t p = 0; p < problem.node.size(); ++p) {
    const double clearance = problem.gap[static_cast<Eigen::Index>(p)] +
                             problem.normal[p].dot(u.segment<3>(3 * problem.node[p]));
    const double push = problem.push[static_cast<Eigen::Index>(p)];
    EXPECT_GE(push, 0);
    EXPECT_GE(clearance, -kTolerance)
        << "node " << body.mesh.node_tags[static_cast<std::size_t>(problem.node[p])]
        << " inside sphere " << problem.tool[p];
    if (push > 0) {
      EXPECT_NEAR(clearance, 0, kTolerance) << "a pushed node is on its sphere";
    }
  }
}

std::vector<std::int64_t> column_tags(const ElasticBody& body, const std::vector<int>& nodes) {
  std::vector<std::int64_t> tags;
  for (int node : nodes) tags.push_back(body.mesh.node_tags[static_cast<std::size_t>(node)]);
  std::sort(tags.begin(), tags.end());
  return tags;
}

// Mesh node tags of the IR's nodes in contact at the evaluation that left `state`.
std::vector<std::int64_t> column_ir_contact_tags(const PreparedIR& prepared,
                                                 const EvaluationState& state) {
  const CondensedFemIr& fem = condensed_fem(prepared.ir);
  std::vector<std::int64_t> tags;
  for (int i = 0; i < fem.row_node_count; ++i)
    if (std::get<FemEvaluation>(state.body).sphere->solve.push(i) > 0)
      tags.push_back(fem.node_ids[static_cast<std::size_t>(i)]);
  std::sort(tags.begin(), tags.end());
  return tags;
}

// Patch rings 1 (the scenes' default) and 0: with 0 rings B's patch is its nearest triangle
// alone (B holds no node at rest), so every other node B pushes reaches the IR only because
// the server adds the triangles of the nodes its solved state has a sphere push.
class SphereOutsideCandidates : public ::testing::TestWithParam<int> {};

TEST_P(SphereOutsideCandidates, ANodeTheColumnCarriesIntoASphereIsHeldAsTheFullSparseSolveHoldsIt) {
  const int patch_rings = GetParam();
  testing::CubeRig rig(kColumnScene);
  const ElasticBody& body = rig.body;
  const ColumnTouchableCompliance compliance = column_touchable_compliance(body);
  const Eigen::Vector3d b_centre =
      mm(10, 0, -5) + Eigen::Vector3d(kColumnSphereRadius + kColumnStandoff, 0, 0);
  int b_pushed = 0, carried_in = 0, b_beyond_one_triangle = 0;
  double worst = 0;
  for (int k = 0; k <= 4; ++k) {
    const double depth = 0.5 + 0.5 * k;  // A's press into the -x face [mm]
    const std::vector<Eigen::Vector3d> centres = {mm(-20 + depth, 0, -5), b_centre};
    SCOPED_TRACE("A " + std::to_string(depth) + " mm deep");

    const ColumnPairProblem expected = solve_every_column_pair(body, compliance, centres);
    expect_column_contact_conditions(body, expected);
    // B holds no node at rest: every one it pushes was carried in.
    for (std::size_t p = 0; p < expected.node.size(); ++p) {
      if (expected.tool[p] == 1) {
        ASSERT_GT(expected.gap[static_cast<Eigen::Index>(p)], 0) << "B holds a node at rest";
      }
      if (expected.push[static_cast<Eigen::Index>(p)] > 0 &&
          expected.gap[static_cast<Eigen::Index>(p)] > 0)
        ++carried_in;
    }
    if (expected.force[1].norm() > 1e-3 * expected.force[0].norm()) ++b_pushed;
    int b_contacts = 0;
    for (std::size_t p = 0; p < expected.node.size(); ++p)
      b_contacts += expected.tool[p] == 1 && expected.push[static_cast<Eigen::Index>(p)] > 0;
    if (b_contacts > 3) ++b_beyond_one_triangle;  // more than B's nearest triangle holds

    // The server's simulation and each user's IR, evaluated at the tools' positions.
    Simulation simulation(body, rig.model->obstacles, *rig.columns, rig.model->scene.tools,
                          testing::unlimited_options(ContactModel::sphere, 0, patch_rings));
    for (int user = 0; user < 2; ++user)
      simulation.set_tool(user, centres[static_cast<std::size_t>(user)]);
    EXPECT_EQ(simulation.step(0).sphere_nodes_outside_patches, 0);
    for (int user = 0; user < 2; ++user) {
      const PreparedIR& prepared = *simulation.ir(user);
      std::vector<Eigen::Vector3d> remotes;
      for (int r = 0; r < remote_count(prepared.ir); ++r)
        remotes.push_back(centres[static_cast<std::size_t>(remote_user(prepared.ir, r))]);
      EvaluationState state = make_evaluation_state(prepared);
      const ForceSample sample =
          evaluate_force(prepared, state, centres[static_cast<std::size_t>(user)], remotes, 1e-3);
      ASSERT_FALSE(sample.flags & (kOutsidePatch | kContactUnresolved | kNonFinite))
          << "user " << user;
      const double error =
          relative_error(sample.force, expected.force[static_cast<std::size_t>(user)]);
      EXPECT_LE(error, 1e-9) << "user " << user << ": IR " << sample.force.transpose()
                             << " N, full solve "
                             << expected.force[static_cast<std::size_t>(user)].transpose() << " N";
      worst = std::max(worst, error);
      EXPECT_EQ(column_ir_contact_tags(prepared, state),
                column_tags(body, expected.contact_nodes()))
          << "user " << user;
    }

    // The sphere model's own full solve.
    const SphereContactSolution reference = sphere_reactions_reference(
        body, {{centres[0], kColumnSphereRadius}, {centres[1], kColumnSphereRadius}});
    for (int t = 0; t < 2; ++t)
      EXPECT_LE(relative_error(reference.reactions[static_cast<std::size_t>(t)],
                               expected.force[static_cast<std::size_t>(t)]),
                1e-9)
          << "reference, sphere " << t;
    EXPECT_EQ(column_tags(body, reference.contact_nodes()),
              column_tags(body, expected.contact_nodes()));
    std::printf("  A %.1f mm deep: |F_A| = %.4f N, |F_B| = %.4f N, %zu nodes in contact\n", depth,
                expected.force[0].norm(), expected.force[1].norm(),
                expected.contact_nodes().size());
  }
  std::printf(
      "  worst relative IR force error %.2e; %d node contacts carried in from outside a sphere\n",
      worst, carried_in);
  // Not vacuous: the model that holds only nodes inside a sphere at rest gives B no force.
  EXPECT_GE(b_pushed, 3);
  EXPECT_GT(carried_in, 0);
  EXPECT_GT(b_beyond_one_triangle, 0) << "with 0 rings, B's IR needs the carried nodes' triangles";
}

INSTANTIATE_TEST_SUITE_P(PatchRings, SphereOutsideCandidates, ::testing::Values(1, 0),
                         [](const ::testing::TestParamInfo<int>& rings) {
                           return "Rings" + std::to_string(rings.param);
                         });

}  // namespace
}  // namespace cohaptic
