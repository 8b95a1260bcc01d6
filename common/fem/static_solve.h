// The reference path: a full sparse static solve with prescribed displacements and loads.
//
// Every dof is one of: fixed (u = 0), prescribed (u = given value) or unknown. The
// unknowns solve K_UU u_U = f_U - K_UC u_C with a CHOLMOD factorisation of K_UU made for
// the set of prescribed dofs, so this is the slow, independent answer that condensation
// is checked against. One solver serves any number of load cases. Units: m, N, N/m.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <span>
#include <vector>

#include "common/fem/assemble_stiffness.h"
#include "common/fem/dof_map.h"
#include "common/fem/sparse_cholesky.h"

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

class ConstrainedStaticSolver {
 public:
  /// Factors K_UU for the given prescribed dofs. Throws Error for a prescribed dof that is
  /// fixed, out of range or given twice; NumericalError if K_UU is not positive definite.
  ConstrainedStaticSolver(const SparseMatrix& stiffness, const DofMap& dofs,
                          std::vector<int> prescribed_dofs);
  ~ConstrainedStaticSolver();

  /// `prescribed_values` aligned with the constructor's dofs [m]; `applied_forces` 3N [N]
  /// or empty. Loads on constrained dofs are carried by the constraint.
  StaticSolution solve(const Eigen::VectorXd& prescribed_values,
                       const Eigen::VectorXd& applied_forces = {}) const;

  /// The compliance between global dofs with every prescribed dof held at zero [m/N]:
  /// entry (i, j) is the displacement of rows[i] under a unit force at columns[j]. Rows
  /// and columns that are fixed or prescribed give zeros. Solved in blocks of 64
  /// right-hand sides.
  Eigen::MatrixXd compliance_block(std::span<const int> rows, std::span<const int> columns) const;

 private:
  const SparseMatrix& stiffness_;
  std::vector<int> prescribed_;
  std::vector<int> unknown_;
  std::unique_ptr<SparseCholesky> factor_;
};

/// One solve: ConstrainedStaticSolver for the prescribed dofs, then solve().
StaticSolution solve_static(const SparseMatrix& stiffness, const DofMap& dofs,
                            const std::vector<PrescribedDisplacement>& prescribed,
                            const Eigen::VectorXd& applied_forces = {});

}  // namespace cohaptic
