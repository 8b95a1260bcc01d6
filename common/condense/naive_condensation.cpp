#include "common/condense/naive_condensation.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <fmt/format.h>

#include "common/condense/dof_blocks.h"
#include "common/util/error.h"

namespace cohaptic {

double cholesky_condition_estimate(const Eigen::MatrixXd& factor) {
  if (factor.rows() == 0) return 1;
  const Eigen::VectorXd diagonal = factor.diagonal().cwiseAbs();
  const double ratio = diagonal.maxCoeff() / diagonal.minCoeff();
  return ratio * ratio;
}

CondensedOperator naive_condensation(ComplianceSource& columns, const DofMap& dofs,
                                     std::span<const int> contact_nodes,
                                     std::span<const int> boundary_nodes) {
  CondensedOperator op;
  op.contact_dofs = free_dofs_of_nodes(dofs, contact_nodes);
  op.boundary_dofs = free_dofs_of_nodes(dofs, boundary_nodes);
  std::vector<int> all = op.contact_dofs;
  all.insert(all.end(), op.boundary_dofs.begin(), op.boundary_dofs.end());
  const auto c = static_cast<Eigen::Index>(op.contact_dofs.size());
  const auto a = static_cast<Eigen::Index>(all.size());

  Eigen::MatrixXd l_aa = gather_compliance(columns, all, all);
  l_aa = 0.5 * (l_aa + l_aa.transpose()).eval();
  const Eigen::LLT<Eigen::MatrixXd> llt(l_aa);
  if (llt.info() != Eigen::Success)
    throw NumericalError(
        fmt::format("L_AA ({} dofs: {} contact, {} boundary) is not positive definite: a node in "
                    "both C and B, or "
                    "coincident nodes?",
                    a, c, a - c));
  // Rows of C of L_AA^-1 = (L_AA^-1 E_C)^T, L_AA symmetric.
  const Eigen::MatrixXd x = llt.solve(Eigen::MatrixXd::Identity(a, c));
  const Eigen::MatrixXd m_ca = x.transpose();
  op.m_cc = 0.5 * (m_ca.leftCols(c) + m_ca.leftCols(c).transpose());
  op.m_cb = m_ca.rightCols(a - c);
  const Eigen::LLT<Eigen::MatrixXd> s_llt(op.m_cc.inverse());
  op.condition_estimate =
      s_llt.info() == Eigen::Success ? cholesky_condition_estimate(s_llt.matrixL()) : INFINITY;
  return op;
}

}  // namespace cohaptic
