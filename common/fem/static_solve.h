// The reference path: a full sparse static solve with prescribed displacements and loads.
//
// Every dof is one of: fixed (u = 0), prescribed (u = given value) or unknown. The
// unknowns solve K_UU u_U = f_U - K_UC u_C with a fresh CHOLMOD factorisation, so this is
// the slow, independent answer that condensation is checked against. Units: m, N, N/m.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "common/fem/assemble_stiffness.h"
#include "common/fem/dof_map.h"

namespace cohaptic {

struct PrescribedDisplacement {
  int dof = 0;       ///< global dof, 3 * node + axis; must not be a fixed dof
  double value = 0;  ///< [m]
};

struct StaticSolution {
  Eigen::VectorXd displacement;  ///< 3N [m]
  /// K u - f_applied, 3N [N]: at fixed and prescribed dofs the force the support (or the
  /// tool) exerts on the body there; zero to round-off elsewhere.
  Eigen::VectorXd reaction;
};

/// `applied_forces` is 3N [N] or empty (no loads); loads on constrained dofs are carried
/// by the constraint. Throws Error for a prescribed dof that is fixed or given twice.
StaticSolution solve_static(const SparseMatrix& stiffness, const DofMap& dofs,
                            const std::vector<PrescribedDisplacement>& prescribed,
                            const Eigen::VectorXd& applied_forces = {});

}  // namespace cohaptic
