#include "common/fem/static_solve.h"

#include <fmt/format.h>

#include <algorithm>

#include "common/util/error.h"

namespace cohaptic {

ConstrainedStaticSolver::ConstrainedStaticSolver(const SparseMatrix& stiffness, const DofMap& dofs,
                                                 std::vector<int> prescribed_dofs)
    : stiffness_(stiffness), prescribed_(std::move(prescribed_dofs)) {
  const auto n = static_cast<int>(stiffness.rows());
  if (n != 3 * dofs.node_count())
    throw Error(fmt::format("static solve: stiffness has {} rows but the dof map {} nodes", n,
                            dofs.node_count()));
  std::vector<bool> constrained(static_cast<std::size_t>(n), false);
  for (int dof = 0; dof < n; ++dof) constrained[dof] = dofs.free_index[dof] < 0;
  for (int dof : prescribed_) {
    if (dof < 0 || dof >= n)
      throw Error(fmt::format("static solve: prescribed dof {} out of range", dof));
    if (dofs.free_index[dof] < 0)
      throw Error(fmt::format("static solve: node {} axis {} is fixed and cannot be prescribed",
                              dof / 3, dof % 3));
    if (constrained[dof])
      throw Error(
          fmt::format("static solve: node {} axis {} is prescribed twice", dof / 3, dof % 3));
    constrained[dof] = true;
  }
  for (int dof = 0; dof < n; ++dof)
    if (!constrained[dof]) unknown_.push_back(dof);
  if (!unknown_.empty())
    factor_ =
        std::make_unique<SparseCholesky>(restrict_to_dofs(stiffness, unknown_), [this](int row) {
          return fmt::format("node {} axis {}", unknown_[row] / 3, unknown_[row] % 3);
        });
}

ConstrainedStaticSolver::~ConstrainedStaticSolver() = default;

StaticSolution ConstrainedStaticSolver::solve(const Eigen::VectorXd& prescribed_values,
                                              const Eigen::VectorXd& applied_forces) const {
  const auto n = stiffness_.rows();
  if (prescribed_values.size() != static_cast<Eigen::Index>(prescribed_.size()))
    throw Error(fmt::format("static solve: {} prescribed values for {} prescribed dofs",
                            prescribed_values.size(), prescribed_.size()));
  if (applied_forces.size() != 0 && applied_forces.size() != n)
    throw Error(fmt::format("static solve: {} applied force components for {} dofs",
                            applied_forces.size(), n));
  StaticSolution solution;
  solution.displacement = Eigen::VectorXd::Zero(n);
  for (std::size_t i = 0; i < prescribed_.size(); ++i)
    solution.displacement[prescribed_[i]] = prescribed_values[static_cast<Eigen::Index>(i)];
  if (factor_) {
    // rhs = f_U - K_UC u_C, computed as (f - K u_C-only)_U.
    Eigen::VectorXd full_rhs = -(stiffness_ * solution.displacement);
    if (applied_forces.size() == n) full_rhs += applied_forces;
    Eigen::VectorXd rhs(static_cast<Eigen::Index>(unknown_.size()));
    for (std::size_t i = 0; i < unknown_.size(); ++i)
      rhs[static_cast<Eigen::Index>(i)] = full_rhs[unknown_[i]];
    const Eigen::VectorXd u_unknown = factor_->solve(rhs);
    for (std::size_t i = 0; i < unknown_.size(); ++i)
      solution.displacement[unknown_[i]] = u_unknown[static_cast<Eigen::Index>(i)];
  }
  solution.reaction = stiffness_ * solution.displacement;
  if (applied_forces.size() == n) solution.reaction -= applied_forces;
  return solution;
}

Eigen::MatrixXd ConstrainedStaticSolver::compliance_block(std::span<const int> rows,
                                                          std::span<const int> columns) const {
  constexpr Eigen::Index kBlock = 64;
  const auto n = static_cast<int>(stiffness_.rows());
  std::vector<int> position(static_cast<std::size_t>(n), -1);  // among the unknowns
  for (std::size_t i = 0; i < unknown_.size(); ++i)
    position[static_cast<std::size_t>(unknown_[i])] = static_cast<int>(i);
  const auto at = [&](int dof) {
    if (dof < 0 || dof >= n)
      throw Error(fmt::format("static solve: compliance of dof {}, out of range", dof));
    return position[static_cast<std::size_t>(dof)];
  };
  const auto row_count = static_cast<Eigen::Index>(rows.size());
  const auto column_count = static_cast<Eigen::Index>(columns.size());
  Eigen::MatrixXd block = Eigen::MatrixXd::Zero(row_count, column_count);
  for (Eigen::Index begin = 0; begin < column_count && factor_; begin += kBlock) {
    const Eigen::Index width = std::min(kBlock, column_count - begin);
    Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(unknown_.size()), width);
    for (Eigen::Index c = 0; c < width; ++c)
      if (const int p = at(columns[static_cast<std::size_t>(begin + c)]); p >= 0) rhs(p, c) = 1;
    const Eigen::MatrixXd x = factor_->solve(rhs);
    for (Eigen::Index r = 0; r < row_count; ++r)
      if (const int p = at(rows[static_cast<std::size_t>(r)]); p >= 0)
        block.row(r).segment(begin, width) = x.row(p);
  }
  return block;
}

StaticSolution solve_static(const SparseMatrix& stiffness, const DofMap& dofs,
                            const std::vector<PrescribedDisplacement>& prescribed,
                            const Eigen::VectorXd& applied_forces) {
  std::vector<int> prescribed_dofs;
  Eigen::VectorXd values(static_cast<Eigen::Index>(prescribed.size()));
  for (std::size_t i = 0; i < prescribed.size(); ++i) {
    prescribed_dofs.push_back(prescribed[i].dof);
    values[static_cast<Eigen::Index>(i)] = prescribed[i].value;
  }
  return ConstrainedStaticSolver(stiffness, dofs, std::move(prescribed_dofs))
      .solve(values, applied_forces);
}

}  // namespace cohaptic
