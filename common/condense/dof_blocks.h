// Dof-level views of node sets: the free dofs of a list of nodes, and blocks of the
// compliance L = K_ff^-1 between such dof lists.
//
// A dof is global (3 * node + axis). Fixed dofs are never listed: their compliance is
// zero and would make every condensed matrix singular. Units of L: m/N.
#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

#include "common/fem/compliance.h"
#include "common/fem/dof_map.h"

namespace cohaptic {

/// Free dofs of `nodes`, node by node, axes in x, y, z order.
std::vector<int> free_dofs_of_nodes(const DofMap& dofs, std::span<const int> nodes);

/// L[row_dofs, col_dofs], from the server's columns or the rows a client holds.
Eigen::MatrixXd gather_compliance(ComplianceSource& columns, std::span<const int> row_dofs,
                                  std::span<const int> col_dofs);

/// Nodes of `dofs` (one entry per distinct node, in order of first appearance).
std::vector<int> nodes_of_dofs(std::span<const int> dofs);

}  // namespace cohaptic
