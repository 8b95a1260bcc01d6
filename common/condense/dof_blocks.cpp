#include "common/condense/dof_blocks.h"

#include <algorithm>

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

Eigen::MatrixXd gather_compliance(ComplianceSource& columns, std::span<const int> row_dofs,
                                  std::span<const int> col_dofs) {
  return columns.dof_block(row_dofs, col_dofs);
}

}  // namespace cohaptic
