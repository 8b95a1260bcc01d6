// The naive path to M~, kept as the reference: gather L_AA for A = C u B, factor it from
// scratch (dense Cholesky, O(|A|^3)) and solve for the rows of C.
#pragma once

#include <span>

#include "common/condense/condensed_operator.h"
#include "common/fem/compliance.h"
#include "common/fem/dof_map.h"

namespace cohaptic {

/// Throws NumericalError (with a condition estimate) if L_AA is not positive definite,
/// e.g. when C and B share a node.
CondensedOperator naive_condensation(ComplianceSource& columns, const DofMap& dofs,
                                     std::span<const int> contact_nodes,
                                     std::span<const int> boundary_nodes);

/// Squared ratio of the largest to the smallest diagonal entry of a Cholesky factor.
double cholesky_condition_estimate(const Eigen::MatrixXd& factor);

}  // namespace cohaptic
