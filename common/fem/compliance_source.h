// ComplianceSource: where a condensation reads blocks of the compliance L = K_ff^-1 from.
// The server reads them from its sparse factor (ComplianceColumns, compliance.h); a haptic
// client reads them from the rows the server sent it (HeldCompliance,
// common/ir/client_condensation.h), so that both condense with the same code (common/condense).
// Dofs are global (3 * node + axis) and free; L in m/N, symmetric.
#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

namespace cohaptic {

class ComplianceSource {
 public:
  virtual ~ComplianceSource() = default;
  /// Makes the columns of `nodes` available before they are read (the server solves them
  /// together, in one multi-right-hand-side solve). Throws Error if it cannot.
  virtual void compute_columns(const std::vector<int>& nodes) = 0;
  /// L[row_dofs, col_dofs]. Throws Error naming the node whose block is not available.
  virtual Eigen::MatrixXd dof_block(std::span<const int> row_dofs,
                                    std::span<const int> col_dofs) = 0;

 protected:
  ComplianceSource() = default;
  ComplianceSource(const ComplianceSource&) = default;
  ComplianceSource& operator=(const ComplianceSource&) = default;
};

}  // namespace cohaptic
