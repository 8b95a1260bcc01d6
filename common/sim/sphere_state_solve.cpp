#include "common/sim/sphere_state_solve.h"

#include <Eigen/Cholesky>

#include <limits>

#include "common/condense/dof_blocks.h"
#include "common/contact/unilateral_contact_solve.h"
#include "common/util/error.h"

namespace cohaptic {

namespace {

// The state with the candidates of `holding` as the working set: they are condensed with B
// held and their unilateral problem solved; every other node is free.
StateSolution solve_over_sphere_set(ComplianceColumns& columns, IncrementalCondensation& condensation, const DofMap& dofs,
                                    const SphereCandidates& holding, std::size_t tool_count,
                                    const Eigen::VectorXd& boundary_displacement) {
  StateSolution state;
  state.tool_forces.assign(tool_count, Eigen::Vector3d::Zero());
  const auto m = static_cast<Eigen::Index>(holding.nodes.size());
  state.contact_dofs = free_dofs_of_nodes(dofs, holding.nodes);
  state.contact_forces = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(state.contact_dofs.size()));
  if (m > 0) {
    const CondensedOperator op = condensation.condense(holding.nodes);
    const Eigen::LLT<Eigen::MatrixXd> llt(op.m_cc);
    if (llt.info() != Eigen::Success) throw NumericalError("the sphere contact's M_CC is not positive definite");
    const Eigen::MatrixXd compliance = llt.solve(Eigen::MatrixXd::Identity(op.m_cc.rows(), op.m_cc.cols()));
    const Eigen::VectorXd free_displacement = -compliance * (op.m_cb * boundary_displacement);
    // Row of each held node's axis in the condensed operator (-1: fixed).
    std::vector<std::array<int, 3>> rows(static_cast<std::size_t>(m), {-1, -1, -1});
    for (int dof = 0, i = 0; i < m; ++i)
      for (int axis = 0; axis < 3; ++axis)
        if (!dofs.is_fixed(holding.nodes[static_cast<std::size_t>(i)], axis)) rows[static_cast<std::size_t>(i)][axis] = dof++;
    const auto normal_part = [&](Eigen::Index i) {  // N's column of node i over the condensed rows
      Eigen::VectorXd column = Eigen::VectorXd::Zero(compliance.rows());
      for (int axis = 0; axis < 3; ++axis)
        if (const int row = rows[static_cast<std::size_t>(i)][axis]; row >= 0)
          column[row] = holding.constraints[static_cast<std::size_t>(i)].normal[axis];
      return column;
    };
    Eigen::MatrixXd normals(compliance.rows(), m);
    for (Eigen::Index i = 0; i < m; ++i) normals.col(i) = normal_part(i);
    Eigen::MatrixXd a = normals.transpose() * compliance * normals;
    a = 0.5 * (a + a.transpose()).eval();
    Eigen::VectorXd q = normals.transpose() * free_displacement;
    for (Eigen::Index i = 0; i < m; ++i) q[i] += holding.constraints[static_cast<std::size_t>(i)].gap;

    std::vector<std::uint8_t> active(static_cast<std::size_t>(m), 0);
    for (Eigen::Index i = 0; i < m; ++i) active[static_cast<std::size_t>(i)] = q[i] < 0;  // a warm start only
    Eigen::VectorXd pushes(m);
    Eigen::MatrixXd factor(m, m);
    std::vector<int> order(static_cast<std::size_t>(m));
    if (!solve_unilateral_contact(a, q, active, pushes, factor, order, std::numeric_limits<double>::infinity()).solved)
      throw NumericalError("the sphere contact's normal compliance is not positive definite");
    state.contact_forces = normals * pushes;
    for (Eigen::Index i = 0; i < m; ++i) {
      const SphereConstraint& c = holding.constraints[static_cast<std::size_t>(i)];
      state.tool_forces[static_cast<std::size_t>(c.tool)] += pushes[i] * c.normal;
    }
  }
  solve_boundary_forces(columns, condensation, dofs, boundary_displacement, state);
  return state;
}

}  // namespace

StateSolution solve_sphere_state(ComplianceColumns& columns, IncrementalCondensation& condensation, const TetMesh& mesh,
                                 const DofMap& dofs, std::span<const int> candidates, std::span<const SphereTool> spheres,
                                 const Eigen::VectorXd& boundary_displacement) {
  std::vector<bool> held_as_boundary(static_cast<std::size_t>(mesh.node_count()), false);
  for (int node : condensation.boundary_nodes()) held_as_boundary[static_cast<std::size_t>(node)] = true;
  std::vector<int> free_candidates;
  for (int node : candidates)
    if (!held_as_boundary[static_cast<std::size_t>(node)]) free_candidates.push_back(node);
  const SphereCandidates all = sphere_candidates(mesh, dofs, free_candidates, spheres);

  // The working set (working_set_contact_solve.h), checked by displacement: it starts as the
  // nodes the spheres hold at rest, and every other candidate that the solved state carries
  // into its sphere joins it, until none does.
  std::vector<bool> in_set(all.nodes.size());
  for (std::size_t i = 0; i < all.nodes.size(); ++i) in_set[i] = all.constraints[i].gap < 0;
  for (;;) {
    SphereCandidates set;
    std::vector<std::size_t> others;
    for (std::size_t i = 0; i < all.nodes.size(); ++i)
      if (in_set[i]) {
        set.nodes.push_back(all.nodes[i]);
        set.constraints.push_back(all.constraints[i]);
      } else {
        others.push_back(i);
      }
    StateSolution state = solve_over_sphere_set(columns, condensation, dofs, set, spheres.size(), boundary_displacement);
    if (others.empty()) return state;
    std::vector<int> other_nodes;
    for (std::size_t i : others) other_nodes.push_back(all.nodes[i]);
    const Eigen::Matrix3Xd u = displacement_of_nodes(columns, state, other_nodes);
    bool joined = false;
    for (std::size_t k = 0; k < others.size(); ++k) {
      const SphereConstraint& c = all.constraints[others[k]];
      if (c.gap + c.normal.dot(u.col(static_cast<Eigen::Index>(k))) < 0) in_set[others[k]] = joined = true;
    }
    if (!joined) return state;
  }
}

}  // namespace cohaptic
