#include "common/condense/dof_blocks.h"

#include <fmt/format.h>

#include <algorithm>

#include "common/util/error.h"

namespace cohaptic {

std::vector<int> free_dofs_of_nodes(const DofMap& dofs, std::span<const int> nodes) {
  std::vector<int> out;
  out.reserve(3 * nodes.size());
  for (int node : nodes)
    for (int axis = 0; axis < 3; ++axis)
      if (!dofs.is_fixed(node, axis)) out.push_back(3 * node + axis);
  return out;
}

std::vector<int> nodes_of_dofs(std::span<const int> dofs) {
  std::vector<int> nodes;
  for (int dof : dofs)
    if (nodes.empty() || nodes.back() != dof / 3) nodes.push_back(dof / 3);
  return nodes;
}

Eigen::MatrixXd gather_compliance(ComplianceColumns& columns, std::span<const int> row_dofs,
                                  std::span<const int> col_dofs) {
  std::vector<int> row_index(row_dofs.size());
  for (std::size_t i = 0; i < row_dofs.size(); ++i) {
    const int position = columns.row_position(row_dofs[i] / 3);
    if (position < 0)
      throw Error(fmt::format("compliance rows are not kept for node {} (not touchable or on the surface)", row_dofs[i] / 3));
    row_index[i] = 3 * position + row_dofs[i] % 3;
  }
  columns.compute_columns(nodes_of_dofs(col_dofs));
  Eigen::MatrixXd block(static_cast<Eigen::Index>(row_dofs.size()), static_cast<Eigen::Index>(col_dofs.size()));
  for (std::size_t j = 0; j < col_dofs.size(); ++j) {
    const ComplianceColumn& column = columns.column(col_dofs[j] / 3);
    const int axis = col_dofs[j] % 3;
    for (std::size_t i = 0; i < row_dofs.size(); ++i)
      block(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = column(row_index[i], axis);
  }
  return block;
}

}  // namespace cohaptic
