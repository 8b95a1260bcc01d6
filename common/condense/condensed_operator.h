// CondensedOperator: the paper's M~ = (M_CC M_CB), the contact rows of M = L_AA^-1 for
// A = C u B (contact nodes C, colliding boundary nodes B), over free dofs.
//
// f_C = M_CC u_C + M_CB u_B gives the forces on the contact dofs for prescribed contact and
// boundary displacements, every other free node carrying no external force. Units: N/m.
// Invariant: m_cc is symmetric positive definite.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace cohaptic {

struct CondensedOperator {
  std::vector<int> contact_dofs;   ///< global free dofs of C, node by node
  std::vector<int> boundary_dofs;  ///< global free dofs of B
  Eigen::MatrixXd m_cc;            ///< |C| x |C|, symmetric
  Eigen::MatrixXd m_cb;            ///< |C| x |B|
  /// Cheap estimate of the condition number of the condensed compliance S = M_CC^-1
  /// (squared ratio of the extreme diagonal entries of its Cholesky factor).
  double condition_estimate = 1;
};

}  // namespace cohaptic
