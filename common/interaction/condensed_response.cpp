#include "common/interaction/condensed_response.h"

#include <fmt/format.h>

#include <Eigen/Cholesky>

#include "common/util/error.h"

namespace cohaptic {
namespace {

// Fills workspace.free_dofs and L_cc over them (its lower triangle; top-left corner of
// workspace.compliance); returns their count.
Eigen::Index gather_free_compliance(ComplianceColumns& columns, const DofMap& dofs,
                                    std::span<const int> nodes,
                                    CondensedResponseWorkspace& workspace) {
  workspace.free_dofs.clear();
  for (std::size_t j = 0; j < nodes.size(); ++j)
    for (int axis = 0; axis < 3; ++axis)
      if (!dofs.is_fixed(nodes[j], axis))
        workspace.free_dofs.push_back(3 * static_cast<int>(j) + axis);
  const auto free_count = static_cast<Eigen::Index>(workspace.free_dofs.size());
  if (workspace.compliance.rows() < free_count) {
    workspace.compliance.resize(free_count, free_count);
    workspace.values.resize(free_count);
  }
  for (Eigen::Index col = 0; col < free_count; ++col) {
    const int col_dof = workspace.free_dofs[static_cast<std::size_t>(col)];
    const ComplianceColumn& column = columns.column(nodes[static_cast<std::size_t>(col_dof / 3)]);
    for (Eigen::Index row = col; row < free_count; ++row) {
      const int row_dof = workspace.free_dofs[static_cast<std::size_t>(row)];
      const int row_position = columns.row_position(nodes[static_cast<std::size_t>(row_dof / 3)]);
      workspace.compliance(row, col) = column(3 * row_position + row_dof % 3, col_dof % 3);
    }
  }
  return free_count;
}

void factor_in_place(Eigen::Ref<Eigen::MatrixXd> compliance, std::span<const int> nodes) {
  const Eigen::LLT<Eigen::Ref<Eigen::MatrixXd>> factor(compliance);
  if (factor.info() != Eigen::Success)
    throw NumericalError(
        fmt::format("the compliance of the {} displaced nodes of the behind body is not positive "
                    "definite (a node listed twice?)",
                    nodes.size()));
}

}  // namespace

void condensed_reaction(ComplianceColumns& columns, const DofMap& dofs, std::span<const int> nodes,
                        const Eigen::Ref<const Eigen::VectorXd>& displacement,
                        Eigen::Ref<Eigen::VectorXd> forces, CondensedResponseWorkspace& workspace) {
  const Eigen::Index free_count = gather_free_compliance(columns, dofs, nodes, workspace);
  auto compliance = workspace.compliance.topLeftCorner(free_count, free_count);
  factor_in_place(compliance, nodes);
  auto values = workspace.values.head(free_count);
  for (Eigen::Index i = 0; i < free_count; ++i)
    values[i] = displacement[workspace.free_dofs[static_cast<std::size_t>(i)]];
  compliance.triangularView<Eigen::Lower>().solveInPlace(values);
  compliance.triangularView<Eigen::Lower>().transpose().solveInPlace(values);
  forces.setZero();
  for (Eigen::Index i = 0; i < free_count; ++i)
    forces[workspace.free_dofs[static_cast<std::size_t>(i)]] = values[i];
}

void condensed_deformation(ComplianceColumns& columns, std::span<const int> nodes,
                           const Eigen::Ref<const Eigen::VectorXd>& forces,
                           Eigen::Ref<Eigen::VectorXd> row_displacement) {
  row_displacement.setZero();
  for (std::size_t j = 0; j < nodes.size(); ++j)
    row_displacement.noalias() +=
        columns.column(nodes[j]) * forces.segment<3>(3 * static_cast<Eigen::Index>(j));
}

Eigen::MatrixXd condensed_stiffness(ComplianceColumns& columns, const DofMap& dofs,
                                    std::span<const int> nodes) {
  CondensedResponseWorkspace workspace;
  const Eigen::Index free_count = gather_free_compliance(columns, dofs, nodes, workspace);
  auto compliance = workspace.compliance.topLeftCorner(free_count, free_count);
  factor_in_place(compliance, nodes);
  Eigen::MatrixXd free_stiffness = Eigen::MatrixXd::Identity(free_count, free_count);
  compliance.triangularView<Eigen::Lower>().solveInPlace(free_stiffness);
  compliance.triangularView<Eigen::Lower>().transpose().solveInPlace(free_stiffness);
  const auto size = 3 * static_cast<Eigen::Index>(nodes.size());
  Eigen::MatrixXd stiffness = Eigen::MatrixXd::Zero(size, size);
  for (Eigen::Index i = 0; i < free_count; ++i)
    for (Eigen::Index j = 0; j < free_count; ++j)
      stiffness(workspace.free_dofs[static_cast<std::size_t>(i)],
                workspace.free_dofs[static_cast<std::size_t>(j)]) =
          0.5 * (free_stiffness(i, j) + free_stiffness(j, i));
  return stiffness;
}

}  // namespace cohaptic
