// FEM against FEM (fem_pair_coupling.h) on the paired boxes (tests/support/fem_pair_rig.h:
// front A and behind B both linear elastic), against independent answers:
// - the pushes and the tool's force equal one sparse solve of A and B together, the
//   contact constraints as Lagrange multipliers (support/joint_pair_solve.h: Eigen's
//   SparseLU on the saddle-point system, no compliance columns and no CHOLMOD), its contact
//   set found by its own active-set loop; the answer meets every condition of the
//   unilateral problem, which has one solution, so the set is the set (1e-9);
// - B's displacement under the pushes equals that solve's (1e-9);
// - A's M~ condensed over its compliance with B folded in as a support (Woodbury,
//   supported_compliance.h) equals M~ condensed over CHOLMOD's factor of K_A with the
//   support springs added (1e-9);
// - a user's IR of A with B folded in equals the IR built over that CHOLMOD factor, and a
//   client completing it from compliance rows of the supported compliance, through the
//   wire, gets its M~ and forces (1e-9); rows of A's own L would lose B;
// - a tool pushing A towards B meets F_free < F_on-B < F_fixed (A's back face fixed).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <unordered_map>
#include <vector>

#include "common/condense/incremental_condensation.h"
#include "common/condense/naive_condensation.h"
#include "common/fem/sparse_cholesky.h"
#include "common/ir/build_ir.h"
#include "common/ir/client_condensation.h"
#include "common/ir/compliance_rows_sender.h"
#include "common/ir/evaluate_force.h"
#include "common/sim/fem_pair_coupling.h"
#include "common/sim/supported_compliance.h"
#include "proto/wire/ir_convert.h"
#include "support/fem_pair_rig.h"
#include "support/joint_pair_solve.h"

namespace cohaptic {
namespace {

// The joint sparse solve (support/joint_pair_solve.h) of the rig's push: the tool's node held.
struct JointPush {
  testing::JointPairSolution solution;
  Eigen::Vector3d tool_force;  // on A by the tool [N]
};

JointPush joint_contact_solve(const testing::PairedBoxesRig& rig, const testing::FreePush& push,
                              const std::vector<PolygonCollision>& collisions) {
  JointPush joint{testing::joint_pair_solve(rig.front, rig.behind, push.tool_dofs, push.tool_values,
                                            collisions),
                  {}};
  for (int axis = 0; axis < 3; ++axis)
    joint.tool_force[axis] =
        joint.solution.front_reaction[push.tool_dofs[static_cast<std::size_t>(axis)]];
  return joint;
}

void expect_joint_solve(const testing::CoupledPush& push) {
  ASSERT_TRUE(push.contact.solved);
  const JointPush joint_push = joint_contact_solve(push.rig, push.free, push.collisions);
  const testing::JointPairSolution& joint = joint_push.solution;
  const double push_scale = joint.pushes.cwiseAbs().maxCoeff();
  ASSERT_GT(push_scale, 0);
  // The joint answer meets every condition of the unilateral problem.
  EXPECT_GE(joint.pushes.minCoeff(), 0);
  EXPECT_GE(joint.gaps.minCoeff(), -1e-12);
  EXPECT_LE(joint.pushes.cwiseProduct(joint.gaps).cwiseAbs().maxCoeff(), 1e-9 * push_scale * 1e-3);
  EXPECT_LE((push.contact.pushes - joint.pushes).cwiseAbs().maxCoeff(), 1e-9 * push_scale);
  EXPECT_LE((push.contact.gaps - joint.gaps).cwiseAbs().maxCoeff(),
            1e-9 * joint.gaps.cwiseAbs().maxCoeff() + 1e-15);
  EXPECT_LE((push.tool_force() - joint_push.tool_force).norm(),
            1e-9 * joint_push.tool_force.norm());
  const Eigen::VectorXd behind =
      behind_pair_displacement(push.collisions, push.contact.pushes, *push.rig.behind_columns);
  double largest = 0, error = 0;
  const std::vector<int>& rows = push.rig.behind_columns->row_nodes();
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const Eigen::Vector3d expected = joint.behind.segment<3>(3 * rows[r]);
    largest = std::max(largest, expected.norm());
    error =
        std::max(error, (behind.segment<3>(3 * static_cast<Eigen::Index>(r)) - expected).norm());
  }
  EXPECT_GT(largest, 0);
  EXPECT_LE(error, 1e-9 * largest);
}

TEST(FemPairCoupling, AToolPushingAIntoBGetsTheJointSparseSolvesPushesAndForce) {
  const testing::CoupledPush push(0.0, 5e-3);
  expect_joint_solve(push);
  EXPECT_GE((push.contact.pushes.array() > 0).count(), 2);
}

TEST(FemPairCoupling, ThroughAGapOnlyTheNodesThatReachBPushAsInTheJointSolve) {
  const testing::CoupledPush push(0.5, 15e-3);
  expect_joint_solve(push);
  const auto pushing = (push.contact.pushes.array() > 0).count();
  EXPECT_GE(pushing, 1);
  EXPECT_LT(pushing, static_cast<Eigen::Index>(
                         push.collisions.size()));  // some candidates stay clear or are released
}

// A pushed 5 mm into B (touching at rest), B folded into A's compliance on the pushing set;
// and, independently, A's compliance from CHOLMOD's factor of K_A with the support springs.
struct FoldedFront {
  testing::CoupledPush push{0.0, 5e-3};
  testing::PushingSupport support = testing::pushing_support(push);
  std::unique_ptr<SupportedCompliance> supported;
  std::unique_ptr<SparseCholesky> factor;
  std::unique_ptr<ComplianceColumns> reference;
  FoldedFront() {
    EXPECT_TRUE(push.contact.solved);
    EXPECT_GE(support.nodes.size(), 2u);
    const ElasticBody& a = push.rig.front;
    supported = std::make_unique<SupportedCompliance>(*push.front_columns, a.dofs, support.nodes,
                                                      support.normals, support.compliance);
    factor = std::make_unique<SparseCholesky>(
        testing::stiffness_with_support(a, support.nodes, support.normals, support.compliance));
    reference = std::make_unique<ComplianceColumns>(*factor, a.dofs, a.surface.nodes);
  }
  int tool_node() const { return push.free.tool_dofs[0] / 3; }
};

TEST(FemPairCoupling, AsMTildeWithBFoldedInEqualsCholmodOnKAWithTheSupportSpringsAdded) {
  FoldedFront folded_front;
  const ElasticBody& a = folded_front.push.rig.front;
  // M~ of the tool's node and its neighbours on the front face, with a top node of the back
  // face held, condensed over each.
  const std::vector<int> contact = testing::tool_neighbourhood(folded_front.push);
  ASSERT_GE(contact.size(), 3u);
  const std::vector<int>& back = folded_front.push.rig.front_face;
  int top = back.front();
  for (int node : back)
    if (a.mesh.nodes(2, node) > a.mesh.nodes(2, top) + 1e-9) top = node;
  const std::vector<int> boundary{top};
  const CondensedOperator folded =
      naive_condensation(*folded_front.supported, a.dofs, contact, boundary);
  const CondensedOperator expected =
      naive_condensation(*folded_front.reference, a.dofs, contact, boundary);
  EXPECT_LE((folded.m_cc - expected.m_cc).norm(), 1e-9 * expected.m_cc.norm());
  EXPECT_GT(expected.m_cb.norm(), 0);
  EXPECT_LE((folded.m_cb - expected.m_cb).norm(), 1e-9 * expected.m_cb.norm());
  // B stiffens A where A presses on it: the tool's condensed stiffness along x grows.
  const CondensedOperator alone =
      naive_condensation(*folded_front.push.front_columns, a.dofs, contact, boundary);
  EXPECT_GT(folded.m_cc(0, 0), alone.m_cc(0, 0));
}

// A user's IR of A with B folded in, for a tool pressing A's front face 1 mm deep, as the
// server builds it over `columns`.
IntermediateRepresentation front_ir(const FoldedFront& folded_front, ComplianceSource& columns,
                                    const Eigen::Vector3d& tool) {
  const ElasticBody& a = folded_front.push.rig.front;
  IncrementalCondensation condensation(columns, a.dofs);
  const std::vector<UserTool> users{{0, tool, 0.0, nearest_touchable_triangle(a, tool), {}}};
  IrBuildOptions options;
  options.force_limit = 1000;  // compare forces, not the limit
  return build_ir(a, condensation, users, 0, {}, options, 1, 0.0);
}

TEST(FemPairCoupling, TheClientFeelsBThroughAExactlyWhenTheRowsAreOfTheSupportedCompliance) {
  FoldedFront folded_front;
  const ElasticBody& a = folded_front.push.rig.front;
  const Eigen::Vector3d tool =
      a.mesh.nodes.col(folded_front.tool_node()) + Eigen::Vector3d(1e-3, 0.7e-3, -0.4e-3);
  const IntermediateRepresentation server = front_ir(folded_front, *folded_front.supported, tool);
  const IntermediateRepresentation reference =
      front_ir(folded_front, *folded_front.reference, tool);
  const Eigen::MatrixXd& m_tilde = condensed_fem(server).m_tilde;
  EXPECT_LE((m_tilde - condensed_fem(reference).m_tilde).norm(), 1e-9 * m_tilde.norm());

  std::unordered_map<std::int64_t, int> mesh_of_tag;
  for (std::size_t i = 0; i < a.mesh.node_tags.size(); ++i)
    mesh_of_tag.emplace(a.mesh.node_tags[i], static_cast<int>(i));
  std::vector<int> mesh_nodes;
  for (const std::int64_t tag : condensed_fem(server).node_ids)
    mesh_nodes.push_back(mesh_of_tag.at(tag));
  // The rows form, through the wire, completed by a client: rows of the supported
  // compliance give the server's M~; rows of A's own L (what the server's sender reads
  // today) would give A without B.
  const auto completed = [&](ComplianceSource& rows_source) {
    IntermediateRepresentation rows = server;
    ComplianceRowsSender sender;
    sender.convert(condensed_fem(rows), mesh_nodes, rows_source, a.dofs);
    IntermediateRepresentation received = wire::from_wire(wire::to_wire(rows));
    ClientCondensation client;
    client.complete(condensed_fem(received));
    return received;
  };
  const IntermediateRepresentation client = completed(*folded_front.supported);
  EXPECT_LE((condensed_fem(client).m_tilde - m_tilde).cwiseAbs().maxCoeff(),
            1e-9 * m_tilde.cwiseAbs().maxCoeff());
  const IntermediateRepresentation without_b = completed(*folded_front.push.front_columns);
  EXPECT_GT((condensed_fem(without_b).m_tilde - m_tilde).cwiseAbs().maxCoeff(),
            1e-3 * m_tilde.cwiseAbs().maxCoeff());

  const PreparedIR on_server = prepare_ir(server);
  const PreparedIR on_client = prepare_ir(client);
  EvaluationState server_state = make_evaluation_state(on_server),
                  client_state = make_evaluation_state(on_client);
  for (const Eigen::Vector3d& offset :
       {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.5e-3, -0.3e-3, 0.2e-3)}) {
    const ForceSample expected = evaluate_force(on_server, server_state, tool + offset, {}, 1e-3);
    const ForceSample felt = evaluate_force(on_client, client_state, tool + offset, {}, 1e-3);
    EXPECT_GT(expected.force.norm(), 0);
    EXPECT_LE((felt.force - expected.force).norm(), 1e-9 * expected.force.norm());
  }
}

TEST(FemPairCoupling, AToolPushingAOnBFeelsMoreThanFreeAndLessThanFixed) {
  for (double depth : {2e-3, 8e-3, 15e-3}) {
    const testing::CoupledPush push(0.0, depth);
    ASSERT_TRUE(push.contact.solved);
    std::vector<int> back_dofs;
    for (int node : push.rig.front_face)
      for (int dof : testing::node_dofs(node))
        if (push.rig.front.dofs.free_index[static_cast<std::size_t>(dof)] >= 0)
          back_dofs.push_back(dof);
    const double fixed =
        testing::push_without_behind(push.rig.front, depth, back_dofs).tool_force.x();
    const double free = push.free.tool_force.x();
    const double on_behind = push.tool_force().x();
    EXPECT_LT(free, on_behind) << depth;
    EXPECT_LT(on_behind, fixed) << depth;
    // The forces [N] as test properties (--gtest_output=xml:...).
    const auto mm = static_cast<int>(std::lround(depth * 1e3));
    RecordProperty(fmt::format("force_{}mm_free_on_b_fixed", mm),
                   fmt::format("{:.6f} {:.6f} {:.6f}", free, on_behind, fixed));
    RecordProperty(
        fmt::format("pushing_nodes_{}mm", mm),
        fmt::format("{} of {}", (push.contact.pushes.array() > 0).count(), push.collisions.size()));
  }
}

}  // namespace
}  // namespace cohaptic
