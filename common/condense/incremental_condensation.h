// IncrementalCondensation: M~ = (M_CC M_CB) without re-inverting when the colliding
// boundary set B changes by one node, or the contact set C changes.
//
// Order A as [B, C]. It keeps
//   - L_BB (dense, free dofs of B, in join order) and its Cholesky factor L_BB = R^T R,
//     updated by bordering when a node joins (O(|B|^2)) and by a rank-k update of the
//     trailing block when one leaves (O(|B|^2));
//   - Z_c = L_BB^-1 L_Bc for recently used contact nodes c, updated alongside (O(|B|)
//     per node and update), computed with two triangular solves for a new node.
// Then S = L_CC - L_CB Z_C (the Schur complement), M_CC = S^-1 and M_CB = -M_CC Z_C^T.
// Every `check_interval` updates it checks the normwise residuals of R and of one Z
// against L_BB; past `drift_tolerance` it refactors from scratch (O(|B|^3)) and counts it.
// Units: compliance m/N, M~ N/m. Not thread-safe; the simulation loop owns it.
#pragma once

#include <Eigen/Core>
#include <span>
#include <unordered_map>
#include <vector>

#include "common/condense/condensed_operator.h"
#include "common/fem/compliance.h"
#include "common/fem/dof_map.h"

namespace cohaptic {

class IncrementalCondensation {
 public:
  struct Options {
    double drift_tolerance = 1e-12;  ///< normwise backward error that triggers a refactorisation
    int check_interval = 32;         ///< updates between residual checks
    std::size_t z_cache_nodes = 64;  ///< contact nodes whose Z columns are kept and updated
    /// condense() refactors L_AA from scratch instead (the paper's conventional loop; makes
    /// the step delay of large boundary sets appear naturally).
    bool naive = false;
  };
  struct Statistics {
    long joins = 0, leaves = 0, residual_checks = 0, refactorizations = 0;
    double last_residual = 0;  ///< largest normwise residual of the last check
  };

  /// `columns` and `dofs` must outlive this object; B and C nodes must be row nodes of `columns`.
  IncrementalCondensation(ComplianceColumns& columns, const DofMap& dofs, Options options);
  IncrementalCondensation(ComplianceColumns& columns, const DofMap& dofs)
      : IncrementalCondensation(columns, dofs, Options{}) {}

  const std::vector<int>& boundary_nodes() const { return b_nodes_; }
  int boundary_dof_count() const { return n_; }
  bool in_boundary(int node) const;

  /// A node joins B (ignored if it has no free dof). Throws Error if already in B,
  /// NumericalError if L_BB would lose positive definiteness (e.g. a coincident node).
  void add_boundary_node(int node);
  /// A node leaves B. Throws Error if it is not in B.
  void remove_boundary_node(int node);
  /// Adds and removes nodes so that B equals `nodes` (order of new joins as given). More
  /// than kBulkJoin new nodes are appended at once and factored from scratch.
  void set_boundary_nodes(std::span<const int> nodes);

  /// M~ for contact nodes `contact_nodes` (none of them in B). Throws NumericalError if the
  /// Schur complement is not positive definite.
  CondensedOperator condense(std::span<const int> contact_nodes);

  /// L_BB^-1 rhs (two triangular solves with R), rhs over the free dofs of B.
  Eigen::MatrixXd solve_boundary(const Eigen::MatrixXd& rhs) const;

  /// Recomputes R and every cached Z from L_BB.
  void refactor();
  const Statistics& statistics() const { return stats_; }

 private:
  static constexpr std::size_t kBulkJoin = 16;
  struct CachedZ {
    Eigen::MatrixXd z;  ///< n x (free dofs of the node)
    long last_used = 0;
  };
  void ensure_capacity(int size);
  void factor_from_scratch(const char* failure);
  void after_update();
  double check_residuals();
  void compute_z(std::span<const int> nodes);
  Eigen::MatrixXd column_rows_at_boundary(int node);  // L[B dofs, free dofs of node]

  ComplianceColumns& columns_;
  const DofMap& dofs_;
  Options options_;
  std::vector<int> b_nodes_;
  std::vector<int> b_dofs_;        // global free dofs of B, in B order
  std::vector<int> b_node_offset_; // first position of each B node's dofs in b_dofs_
  int n_ = 0;                      // |b_dofs_|
  Eigen::MatrixXd l_bb_;           // capacity buffer; top-left n x n is L_BB
  Eigen::MatrixXd r_;              // capacity buffer; top-left n x n is R (upper)
  std::unordered_map<int, CachedZ> z_;
  long clock_ = 0;
  int updates_since_check_ = 0;
  Statistics stats_;
};

}  // namespace cohaptic
