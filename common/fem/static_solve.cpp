#include "common/fem/static_solve.h"

#include <fmt/format.h>

#include "common/fem/sparse_cholesky.h"
#include "common/util/error.h"

namespace cohaptic {

StaticSolution solve_static(const SparseMatrix& stiffness, const DofMap& dofs,
                            const std::vector<PrescribedDisplacement>& prescribed,
                            const Eigen::VectorXd& applied_forces) {
  const auto n = static_cast<int>(stiffness.rows());
  if (n != 3 * dofs.node_count())
    throw Error(fmt::format("static solve: stiffness has {} rows but the dof map {} nodes", n, dofs.node_count()));
  if (applied_forces.size() != 0 && applied_forces.size() != n)
    throw Error(fmt::format("static solve: {} applied force components for {} dofs", applied_forces.size(), n));

  StaticSolution solution;
  solution.displacement = Eigen::VectorXd::Zero(n);
  std::vector<bool> constrained(static_cast<std::size_t>(n), false);
  for (int dof = 0; dof < n; ++dof) constrained[dof] = dofs.free_index[dof] < 0;
  for (const PrescribedDisplacement& p : prescribed) {
    if (p.dof < 0 || p.dof >= n) throw Error(fmt::format("static solve: prescribed dof {} out of range", p.dof));
    if (dofs.free_index[p.dof] < 0)
      throw Error(fmt::format("static solve: node {} axis {} is fixed and cannot be prescribed", p.dof / 3, p.dof % 3));
    if (constrained[p.dof])
      throw Error(fmt::format("static solve: node {} axis {} is prescribed twice", p.dof / 3, p.dof % 3));
    constrained[p.dof] = true;
    solution.displacement[p.dof] = p.value;
  }

  std::vector<int> unknown;
  for (int dof = 0; dof < n; ++dof)
    if (!constrained[dof]) unknown.push_back(dof);
  if (!unknown.empty()) {
    // rhs = f_U - K_UC u_C, computed as (f - K u_C-only)_U.
    Eigen::VectorXd full_rhs = -(stiffness * solution.displacement);
    if (applied_forces.size() == n) full_rhs += applied_forces;
    Eigen::VectorXd rhs(static_cast<Eigen::Index>(unknown.size()));
    for (std::size_t i = 0; i < unknown.size(); ++i) rhs[static_cast<Eigen::Index>(i)] = full_rhs[unknown[i]];
    const SparseCholesky factor(restrict_to_dofs(stiffness, unknown),
                                [&](int row) { return fmt::format("node {} axis {}", unknown[row] / 3, unknown[row] % 3); });
    const Eigen::VectorXd u_unknown = factor.solve(rhs);
    for (std::size_t i = 0; i < unknown.size(); ++i) solution.displacement[unknown[i]] = u_unknown[static_cast<Eigen::Index>(i)];
  }
  solution.reaction = stiffness * solution.displacement;
  if (applied_forces.size() == n) solution.reaction -= applied_forces;
  return solution;
}

}  // namespace cohaptic
