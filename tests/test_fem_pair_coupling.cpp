// FEM against FEM (fem_pair_coupling.h) on the paired boxes (tests/support/fem_pair_rig.h:
// front A and behind B both linear elastic), against independent answers:
// - the pushes and the tool's force equal one sparse solve of A and B together, the
//   contact constraints as Lagrange multipliers (Eigen's SparseLU on the saddle-point
//   system, no compliance columns and no CHOLMOD), its contact set found by its own
//   active-set loop; the answer meets every condition of the unilateral problem, which has
//   one solution, so the set is the set (1e-9);
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

#include <Eigen/SparseLU>
#include <algorithm>
#include <cmath>
#include <memory>
#include <unordered_map>
#include <vector>

#include "common/condense/incremental_condensation.h"
#include "common/condense/naive_condensation.h"
#include "common/fem/assemble_stiffness.h"
#include "common/fem/sparse_cholesky.h"
#include "common/ir/build_ir.h"
#include "common/ir/client_condensation.h"
#include "common/ir/compliance_rows_sender.h"
#include "common/ir/evaluate_force.h"
#include "common/sim/fem_pair_coupling.h"
#include "common/sim/supported_compliance.h"
#include "proto/wire/ir_convert.h"
#include "support/fem_pair_rig.h"

namespace cohaptic {
namespace {

// The sparse solve of A and B together: unknowns A's free dofs but the tool's, B's free
// dofs, and one multiplier (push) per collision of the set; each pushing collision's gap is
// zero. Gaps measured as the collisions measure them (normal offset from the polygon's plane).
struct JointSolution {
  Eigen::VectorXd pushes;  // per collision, zero outside the set [N]
  Eigen::VectorXd gaps;    // per collision [m]
  Eigen::VectorXd front, behind;  // 3N each [m]
  Eigen::Vector3d tool_force;     // on A by the tool [N]
};

JointSolution joint_sparse_solve(const testing::PairedBoxesRig& rig, const testing::FreePush& push,
                                 const std::vector<PolygonCollision>& collisions, const std::vector<bool>& in_set) {
  const ElasticBody& a = rig.front;
  const ElasticBody& b = rig.behind;
  std::vector<int> a_index(static_cast<std::size_t>(3 * a.mesh.node_count()), -1);
  std::vector<int> b_index(static_cast<std::size_t>(3 * b.mesh.node_count()), -1);
  int unknowns = 0;
  std::vector<bool> is_tool(a_index.size(), false);
  for (int dof : push.tool_dofs) is_tool[static_cast<std::size_t>(dof)] = true;
  for (int dof : a.dofs.free_dofs)
    if (!is_tool[static_cast<std::size_t>(dof)]) a_index[static_cast<std::size_t>(dof)] = unknowns++;
  for (int dof : b.dofs.free_dofs) b_index[static_cast<std::size_t>(dof)] = unknowns++;
  std::vector<int> multiplier(collisions.size(), -1);
  for (std::size_t j = 0; j < collisions.size(); ++j)
    if (in_set[j]) multiplier[j] = unknowns++;

  std::vector<Eigen::Triplet<double>> entries;
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(unknowns);
  Eigen::VectorXd tool = Eigen::VectorXd::Zero(a.stiffness.rows());
  for (std::size_t k = 0; k < push.tool_dofs.size(); ++k) tool[push.tool_dofs[k]] = push.tool_values[static_cast<Eigen::Index>(k)];
  const Eigen::VectorXd tool_load = a.stiffness * tool;
  for (int outer = 0; outer < a.stiffness.outerSize(); ++outer)
    for (SparseMatrix::InnerIterator it(a.stiffness, outer); it; ++it) {
      const int row = a_index[static_cast<std::size_t>(it.row())], col = a_index[static_cast<std::size_t>(it.col())];
      if (row >= 0 && col >= 0) entries.emplace_back(row, col, it.value());
    }
  for (std::size_t dof = 0; dof < a_index.size(); ++dof)
    if (a_index[dof] >= 0) rhs[a_index[dof]] = -tool_load[static_cast<Eigen::Index>(dof)];
  for (int outer = 0; outer < b.stiffness.outerSize(); ++outer)
    for (SparseMatrix::InnerIterator it(b.stiffness, outer); it; ++it) {
      const int row = b_index[static_cast<std::size_t>(it.row())], col = b_index[static_cast<std::size_t>(it.col())];
      if (row >= 0 && col >= 0) entries.emplace_back(row, col, it.value());
    }
  // K_A u_A - n lambda = ..., K_B u_B + w n lambda = 0, -n.u_A + n.(sum w u_B) = g0.
  for (std::size_t j = 0; j < collisions.size(); ++j) {
    if (multiplier[j] < 0) continue;
    const PolygonCollision& c = collisions[j];
    for (int axis = 0; axis < 3; ++axis) {
      if (const int row = a_index[static_cast<std::size_t>(3 * c.active + axis)]; row >= 0) {
        entries.emplace_back(row, multiplier[j], -c.normal[axis]);
        entries.emplace_back(multiplier[j], row, -c.normal[axis]);
      }
      for (int k = 0; k < 3; ++k)
        if (const int row = b_index[static_cast<std::size_t>(3 * c.polygon[static_cast<std::size_t>(k)] + axis)]; row >= 0) {
          entries.emplace_back(row, multiplier[j], c.weights[k] * c.normal[axis]);
          entries.emplace_back(multiplier[j], row, c.weights[k] * c.normal[axis]);
        }
    }
    const Eigen::Vector3d rest = a.mesh.nodes.col(c.active) + tool.segment<3>(3 * c.active);
    rhs[multiplier[j]] = (rest - c.target).dot(c.normal);
  }
  Eigen::SparseMatrix<double> system(unknowns, unknowns);
  system.setFromTriplets(entries.begin(), entries.end());
  Eigen::SparseLU<Eigen::SparseMatrix<double>> lu(system);
  EXPECT_EQ(lu.info(), Eigen::Success);
  const Eigen::VectorXd x = lu.solve(rhs);

  JointSolution solution;
  solution.front = tool;
  solution.behind = Eigen::VectorXd::Zero(b.stiffness.rows());
  for (std::size_t dof = 0; dof < a_index.size(); ++dof)
    if (a_index[dof] >= 0) solution.front[static_cast<Eigen::Index>(dof)] = x[a_index[dof]];
  for (std::size_t dof = 0; dof < b_index.size(); ++dof)
    if (b_index[dof] >= 0) solution.behind[static_cast<Eigen::Index>(dof)] = x[b_index[dof]];
  const auto count = static_cast<Eigen::Index>(collisions.size());
  solution.pushes = Eigen::VectorXd::Zero(count);
  solution.gaps.resize(count);
  for (Eigen::Index j = 0; j < count; ++j) {
    const PolygonCollision& c = collisions[static_cast<std::size_t>(j)];
    if (multiplier[static_cast<std::size_t>(j)] >= 0) solution.pushes[j] = x[multiplier[static_cast<std::size_t>(j)]];
    Eigen::Vector3d target = c.target;
    for (int k = 0; k < 3; ++k) target += c.weights[k] * solution.behind.segment<3>(3 * c.polygon[static_cast<std::size_t>(k)]);
    solution.gaps[j] = (a.mesh.nodes.col(c.active) + solution.front.segment<3>(3 * c.active) - target).dot(c.normal);
  }
  const Eigen::VectorXd reaction = a.stiffness * solution.front;
  for (int axis = 0; axis < 3; ++axis) solution.tool_force[axis] = reaction[push.tool_dofs[static_cast<std::size_t>(axis)]];
  return solution;
}

// The joint solve's own active set: start from the penetrating candidates, drop pulling
// ones, add penetrating ones, until none is left to move.
JointSolution joint_contact_solve(const testing::PairedBoxesRig& rig, const testing::FreePush& push,
                                  const std::vector<PolygonCollision>& collisions) {
  std::vector<bool> in_set(collisions.size());
  for (std::size_t j = 0; j < collisions.size(); ++j) in_set[j] = collisions[j].gap.dot(collisions[j].normal) < 0;
  for (int pass = 0; pass < 50; ++pass) {
    JointSolution solution = joint_sparse_solve(rig, push, collisions, in_set);
    bool moved = false;
    for (std::size_t j = 0; j < collisions.size(); ++j) {
      const auto i = static_cast<Eigen::Index>(j);
      if (in_set[j] ? solution.pushes[i] < 0 : solution.gaps[i] < 0) {
        in_set[j] = !in_set[j];
        moved = true;
      }
    }
    if (!moved) return solution;
  }
  ADD_FAILURE() << "the joint solve's active set did not settle";
  return {};
}


void expect_joint_solve(const testing::CoupledPush& push) {
  ASSERT_TRUE(push.contact.solved);
  const JointSolution joint = joint_contact_solve(push.rig, push.free, push.collisions);
  const double push_scale = joint.pushes.cwiseAbs().maxCoeff();
  ASSERT_GT(push_scale, 0);
  // The joint answer meets every condition of the unilateral problem.
  EXPECT_GE(joint.pushes.minCoeff(), 0);
  EXPECT_GE(joint.gaps.minCoeff(), -1e-12);
  EXPECT_LE(joint.pushes.cwiseProduct(joint.gaps).cwiseAbs().maxCoeff(), 1e-9 * push_scale * 1e-3);
  EXPECT_LE((push.contact.pushes - joint.pushes).cwiseAbs().maxCoeff(), 1e-9 * push_scale);
  EXPECT_LE((push.contact.gaps - joint.gaps).cwiseAbs().maxCoeff(), 1e-9 * joint.gaps.cwiseAbs().maxCoeff() + 1e-15);
  EXPECT_LE((push.tool_force() - joint.tool_force).norm(), 1e-9 * joint.tool_force.norm());
  const Eigen::VectorXd behind = behind_pair_displacement(push.collisions, push.contact.pushes, *push.rig.behind_columns);
  double largest = 0, error = 0;
  const std::vector<int>& rows = push.rig.behind_columns->row_nodes();
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const Eigen::Vector3d expected = joint.behind.segment<3>(3 * rows[r]);
    largest = std::max(largest, expected.norm());
    error = std::max(error, (behind.segment<3>(3 * static_cast<Eigen::Index>(r)) - expected).norm());
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
  EXPECT_LT(pushing, static_cast<Eigen::Index>(push.collisions.size()));  // some candidates stay clear or are released
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
    supported = std::make_unique<SupportedCompliance>(*push.front_columns, a.dofs, support.nodes, support.normals,
                                                      support.compliance);
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
  const CondensedOperator folded = naive_condensation(*folded_front.supported, a.dofs, contact, boundary);
  const CondensedOperator expected = naive_condensation(*folded_front.reference, a.dofs, contact, boundary);
  EXPECT_LE((folded.m_cc - expected.m_cc).norm(), 1e-9 * expected.m_cc.norm());
  EXPECT_GT(expected.m_cb.norm(), 0);
  EXPECT_LE((folded.m_cb - expected.m_cb).norm(), 1e-9 * expected.m_cb.norm());
  // B stiffens A where A presses on it: the tool's condensed stiffness along x grows.
  const CondensedOperator alone = naive_condensation(*folded_front.push.front_columns, a.dofs, contact, boundary);
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
  const Eigen::Vector3d tool = a.mesh.nodes.col(folded_front.tool_node()) + Eigen::Vector3d(1e-3, 0.7e-3, -0.4e-3);
  const IntermediateRepresentation server = front_ir(folded_front, *folded_front.supported, tool);
  const IntermediateRepresentation reference = front_ir(folded_front, *folded_front.reference, tool);
  const Eigen::MatrixXd& m_tilde = condensed_fem(server).m_tilde;
  EXPECT_LE((m_tilde - condensed_fem(reference).m_tilde).norm(), 1e-9 * m_tilde.norm());

  std::unordered_map<std::int64_t, int> mesh_of_tag;
  for (std::size_t i = 0; i < a.mesh.node_tags.size(); ++i) mesh_of_tag.emplace(a.mesh.node_tags[i], static_cast<int>(i));
  std::vector<int> mesh_nodes;
  for (const std::int64_t tag : condensed_fem(server).node_ids) mesh_nodes.push_back(mesh_of_tag.at(tag));
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
  EXPECT_LE((condensed_fem(client).m_tilde - m_tilde).cwiseAbs().maxCoeff(), 1e-9 * m_tilde.cwiseAbs().maxCoeff());
  const IntermediateRepresentation without_b = completed(*folded_front.push.front_columns);
  EXPECT_GT((condensed_fem(without_b).m_tilde - m_tilde).cwiseAbs().maxCoeff(), 1e-3 * m_tilde.cwiseAbs().maxCoeff());

  const PreparedIR on_server = prepare_ir(server);
  const PreparedIR on_client = prepare_ir(client);
  EvaluationState server_state = make_evaluation_state(on_server), client_state = make_evaluation_state(on_client);
  for (const Eigen::Vector3d& offset : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.5e-3, -0.3e-3, 0.2e-3)}) {
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
        if (push.rig.front.dofs.free_index[static_cast<std::size_t>(dof)] >= 0) back_dofs.push_back(dof);
    const double fixed = testing::push_without_behind(push.rig.front, depth, back_dofs).tool_force.x();
    const double free = push.free.tool_force.x();
    const double on_behind = push.tool_force().x();
    EXPECT_LT(free, on_behind) << depth;
    EXPECT_LT(on_behind, fixed) << depth;
    // The forces [N] for the closing note (--gtest_output=xml:...).
    const auto mm = static_cast<int>(std::lround(depth * 1e3));
    RecordProperty(fmt::format("force_{}mm_free_on_b_fixed", mm), fmt::format("{:.6f} {:.6f} {:.6f}", free, on_behind, fixed));
    RecordProperty(fmt::format("pushing_nodes_{}mm", mm),
                   fmt::format("{} of {}", (push.contact.pushes.array() > 0).count(), push.collisions.size()));
  }
}

}  // namespace
}  // namespace cohaptic
