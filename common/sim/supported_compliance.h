// SupportedCompliance: the compliance of a linear elastic body A resting on an elastic
// support at some of its nodes, read through the ComplianceSource interface, so that a
// condensation (M~ of A's IR, common/condense) formed over it feels the support.
//
// The support acts along one normal per supporting node s (unit n_s): a push lambda along
// n_s moves the support back by A_S lambda (A_S the support's normal compliance,
// symmetric positive semidefinite), i.e. a stiffness N A_S^-1 N^T on A's nodes S. With L
// A's own compliance, Woodbury gives, on blocks A already holds,
//   L'_XY = L_XY - L_XS N (A_S + N^T L_SS N)^-1 N^T L_SY,
// equal to inverting K_A with the support springs added (defined also where A_S is
// singular, e.g. a support that cannot give way). The support is bilateral: this is the
// compliance while the supporting set stays the same; a caller that finds nodes released
// or added builds another (fem_pair_coupling.h: the behind body B as the support of the
// front body's pushing nodes). A supporting node that was g0 clear of the support at rest
// (along its normal) is held on it: the support also loads A at rest, by the pushes
// lambda0 = -(A_S + N^T L_SS N)^-1 g0 that close those gaps with nothing else held, which
// displace A by u0 = L N lambda0 (rest_displacement; zero when every node touches at rest).
// Units: m/N, m; dofs global (3 * node + axis) and free.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <span>
#include <vector>

#include "common/fem/compliance_source.h"
#include "common/fem/dof_map.h"

namespace cohaptic {

class SupportedCompliance final : public ComplianceSource {
 public:
  /// `base` (A's L over its free dofs under `dofs`; outlives this) must hold rows for every
  /// node asked for and for `nodes` (S, one normal each, the columns of `normals`);
  /// `support_compliance` A_S is |S| square; `rest_gaps` g0 per node of S, or empty (all
  /// zero). Throws Error if A_S + N^T L_SS N is not positive definite.
  SupportedCompliance(ComplianceSource& base, const DofMap& dofs, std::vector<int> nodes,
                      const Eigen::Matrix3Xd& normals, const Eigen::MatrixXd& support_compliance,
                      const Eigen::VectorXd& rest_gaps = {});

  void compute_columns(const std::vector<int>& nodes) override;
  Eigen::MatrixXd dof_block(std::span<const int> row_dofs, std::span<const int> col_dofs) override;

  const std::vector<int>& support_nodes() const { return nodes_; }
  /// False when every node of S touched the support at rest (g0 all zero): nothing loads A.
  bool loads_at_rest() const { return rest_loads_.size() != 0; }
  /// u0 at free dofs `dofs` [m]: A's displacement at rest, the support holding S on it.
  Eigen::VectorXd rest_displacement(std::span<const int> dofs);

 private:
  ComplianceSource& base_;
  std::vector<int> nodes_;
  std::vector<int> dofs_;                // the support nodes' free dofs
  Eigen::SparseMatrix<double> normals_;  // N over those dofs, |dofs_| x |S|: one entry per dof
  Eigen::LLT<Eigen::MatrixXd> coupled_;  // of A_S + N^T L_SS N
  Eigen::VectorXd rest_loads_;           // N lambda0 over dofs_ [N]; empty when g0 = 0
};

}  // namespace cohaptic
