#include "support/joint_pair_solve.h"

#include <gtest/gtest.h>

#include <Eigen/SparseLU>

#include "common/fem/assemble_stiffness.h"

namespace cohaptic::testing {
namespace {

// The solve for one contact set `in_set`; `held` is A's held displacement, 3 per node.
JointPairSolution joint_pair_solve_for_set(const ElasticBody& a, const ElasticBody& b,
                                           const Eigen::VectorXd& held,
                                           const std::vector<bool>& is_held,
                                           const std::vector<PolygonCollision>& collisions,
                                           const std::vector<bool>& in_set) {
  std::vector<int> a_index(static_cast<std::size_t>(3 * a.mesh.node_count()), -1);
  std::vector<int> b_index(static_cast<std::size_t>(3 * b.mesh.node_count()), -1);
  int unknowns = 0;
  for (int dof : a.dofs.free_dofs)
    if (!is_held[static_cast<std::size_t>(dof)])
      a_index[static_cast<std::size_t>(dof)] = unknowns++;
  for (int dof : b.dofs.free_dofs) b_index[static_cast<std::size_t>(dof)] = unknowns++;
  std::vector<int> multiplier(collisions.size(), -1);
  for (std::size_t j = 0; j < collisions.size(); ++j)
    if (in_set[j]) multiplier[j] = unknowns++;

  std::vector<Eigen::Triplet<double>> entries;
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(unknowns);
  const Eigen::VectorXd held_load = a.stiffness * held;
  for (int outer = 0; outer < a.stiffness.outerSize(); ++outer)
    for (SparseMatrix::InnerIterator it(a.stiffness, outer); it; ++it) {
      const int row = a_index[static_cast<std::size_t>(it.row())],
                col = a_index[static_cast<std::size_t>(it.col())];
      if (row >= 0 && col >= 0) entries.emplace_back(row, col, it.value());
    }
  for (std::size_t dof = 0; dof < a_index.size(); ++dof)
    if (a_index[dof] >= 0) rhs[a_index[dof]] = -held_load[static_cast<Eigen::Index>(dof)];
  for (int outer = 0; outer < b.stiffness.outerSize(); ++outer)
    for (SparseMatrix::InnerIterator it(b.stiffness, outer); it; ++it) {
      const int row = b_index[static_cast<std::size_t>(it.row())],
                col = b_index[static_cast<std::size_t>(it.col())];
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
        if (const int row = b_index[static_cast<std::size_t>(
                3 * c.polygon[static_cast<std::size_t>(k)] + axis)];
            row >= 0) {
          entries.emplace_back(row, multiplier[j], c.weights[k] * c.normal[axis]);
          entries.emplace_back(multiplier[j], row, c.weights[k] * c.normal[axis]);
        }
    }
    const Eigen::Vector3d rest = a.mesh.nodes.col(c.active) + held.segment<3>(3 * c.active);
    rhs[multiplier[j]] = (rest - c.target).dot(c.normal);
  }
  Eigen::SparseMatrix<double> system(unknowns, unknowns);
  system.setFromTriplets(entries.begin(), entries.end());
  Eigen::SparseLU<Eigen::SparseMatrix<double>> lu(system);
  EXPECT_EQ(lu.info(), Eigen::Success);
  const Eigen::VectorXd x = lu.solve(rhs);

  JointPairSolution solution;
  solution.front = held;
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
    if (multiplier[static_cast<std::size_t>(j)] >= 0)
      solution.pushes[j] = x[multiplier[static_cast<std::size_t>(j)]];
    Eigen::Vector3d target = c.target;
    for (int k = 0; k < 3; ++k)
      target +=
          c.weights[k] * solution.behind.segment<3>(3 * c.polygon[static_cast<std::size_t>(k)]);
    solution.gaps[j] =
        (a.mesh.nodes.col(c.active) + solution.front.segment<3>(3 * c.active) - target)
            .dot(c.normal);
  }
  solution.front_reaction = a.stiffness * solution.front;
  return solution;
}

}  // namespace

JointPairSolution joint_pair_solve(const ElasticBody& front, const ElasticBody& behind,
                                   std::span<const int> held_dofs,
                                   const Eigen::VectorXd& held_values,
                                   const std::vector<PolygonCollision>& collisions) {
  Eigen::VectorXd held = Eigen::VectorXd::Zero(front.stiffness.rows());
  std::vector<bool> is_held(static_cast<std::size_t>(held.size()), false);
  for (std::size_t k = 0; k < held_dofs.size(); ++k) {
    held[held_dofs[k]] = held_values[static_cast<Eigen::Index>(k)];
    is_held[static_cast<std::size_t>(held_dofs[k])] = true;
  }
  std::vector<bool> in_set(collisions.size());
  for (std::size_t j = 0; j < collisions.size(); ++j)
    in_set[j] = collisions[j].gap.dot(collisions[j].normal) < 0;
  for (int pass = 0; pass < 50; ++pass) {
    JointPairSolution solution =
        joint_pair_solve_for_set(front, behind, held, is_held, collisions, in_set);
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

}  // namespace cohaptic::testing
