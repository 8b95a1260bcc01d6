// IncrementalCondensation: M~ = (M_CC M_CB) without re-inverting when the colliding
// boundary set B changes by one node, or the contact set C changes.
//
// Order A as [B, C]; n = free dofs of B, k <= 3 those of the node that changes. It keeps
//   - L_BB (lower triangle; B in join order) and its Cholesky factor L_BB = G G^T (G lower,
//     the R^T of R^T R). A join borders G: one solve g = G^-1 l with the new columns l. A
//     leave drops the node's rows and columns and updates the block below by rank k with
//     the rows it drops (dense_kernels.h). Each O(n^2), never O(n^3).
//   - Z_c = L_BB^-1 L_Bc and L_Bc for recently used contact nodes c. A join appends k rows
//     and corrects the old ones by rank k (one more solve, q = G^-T g = L_BB^-1 l); a leave
//     drops k rows and corrects the rest by rank k (the node's columns of L_BB^-1, two
//     solves). O(n^2 + n |Z|) per change, |Z| the cached columns.
// condense(C) forms S = L_CC - L_BC^T Z_C, M_CC = S^-1 and M_CB = -M_CC Z_C^T: O(n |C|^2),
// with no solve against L_BB unless a contact node is new to the cache (then two solves
// for all the new ones together, O(n^2 |new|): a column never seen cannot cost less).
// Every `check_interval` updates it checks the normwise residuals of G and of one Z
// against L_BB; past `drift_tolerance` it refactors from scratch (O(n^3)) and counts it.
// Units: compliance m/N, M~ N/m. Not thread-safe; the simulation loop owns it.
#pragma once

#include <Eigen/Core>
#include <span>
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
    /// Wall time spent so far, ms: on the factor G (bordering, rank-k update, moving
    /// rows, refactorisations, residual checks), on the cached Z (their corrections and
    /// new columns), on S and M_CC = S^-1, and on M_CB.
    double factor_ms = 0, z_ms = 0, schur_ms = 0, m_cb_ms = 0;
  };

  /// `columns` and `dofs` must outlive this object; B and C nodes must be row nodes of `columns`.
  /// A copy reads the same `columns` (a cache of what does not change).
  IncrementalCondensation(ComplianceSource& columns, const DofMap& dofs, Options options);
  IncrementalCondensation(ComplianceSource& columns, const DofMap& dofs)
      : IncrementalCondensation(columns, dofs, Options{}) {}
  /// A copy of `other` that reads `columns` instead: a copy of other's source, which has
  /// state of its own (supported_compliance.h).
  IncrementalCondensation(const IncrementalCondensation& other, ComplianceSource& columns)
      : IncrementalCondensation(other) {
    columns_ = &columns;
  }

  const std::vector<int>& boundary_nodes() const { return b_nodes_; }
  int boundary_dof_count() const { return n_; }
  bool in_boundary(int node) const;

  /// A node joins B (ignored if it has no free dof). Throws Error if already in B,
  /// NumericalError if L_BB would lose positive definiteness (e.g. a coincident node).
  void add_boundary_node(int node);
  /// A node leaves B. Throws Error if it is not in B.
  void remove_boundary_node(int node);
  /// Forgets `node` (a client drops it when the server stops sending its rows): it leaves B
  /// if it is in it, and its cached Z column is dropped, so that nothing reads its
  /// compliance again. Nothing happens for a node it does not know.
  void forget_node(int node);
  /// Adds and removes nodes so that B equals `nodes` (order of new joins as given). More
  /// than kBulkJoin new nodes are appended at once and factored from scratch.
  void set_boundary_nodes(std::span<const int> nodes);

  /// M~ for contact nodes `contact_nodes` (none of them in B). Throws NumericalError if the
  /// Schur complement is not positive definite.
  CondensedOperator condense(std::span<const int> contact_nodes);

  /// L_BB^-1 rhs (two triangular solves with G), rhs over the free dofs of B.
  Eigen::MatrixXd solve_boundary(const Eigen::MatrixXd& rhs) const;

  /// Recomputes G and every cached Z from L_BB.
  void refactor();
  const Statistics& statistics() const { return stats_; }

 private:
  static constexpr std::size_t kBulkJoin = 16;
  /// A contact node whose Z_c and L_Bc are kept: slot s holds them in columns
  /// [3s, 3s + width) of z_ and l_bz_, the remaining 3 - width columns zero.
  struct CachedNode {
    int node;
    int width;  ///< free dofs of the node
    long last_used;
  };
  void ensure_row_capacity(int rows);
  void ensure_slot_capacity(std::size_t slots);
  int slot_of(int node) const;  ///< -1 if not cached
  Eigen::Index cached_columns() const { return 3 * static_cast<Eigen::Index>(cached_.size()); }
  /// L[row_dofs, dofs of the cached slots from first_slot on], in the slots' column layout.
  Eigen::MatrixXd compliance_to_slots(std::span<const int> row_dofs, std::size_t first_slot);
  void update_cached_z_for_join(std::span<const int> new_dofs, const Eigen::MatrixXd& l,
                                const Eigen::MatrixXd& g, const Eigen::MatrixXd& rho_lower);
  void update_cached_z_for_leave(int first, int k);
  void forget_least_recently_used();
  void drop_slot(std::size_t slot);
  void factor_from_scratch(const char* failure);
  void after_update();
  double check_residuals();
  void compute_z(std::span<const int> nodes);
  Eigen::MatrixXd column_rows_at_boundary(int node);  // L[B dofs, free dofs of node]

  ComplianceSource* columns_;  // never null
  const DofMap& dofs_;
  Options options_;
  std::vector<int> b_nodes_;
  std::vector<int> b_dofs_;         // global free dofs of B, in B order
  std::vector<int> b_node_offset_;  // first position of each B node's dofs in b_dofs_
  int n_ = 0;                       // |b_dofs_|
  // Capacity buffers, all with the same number of rows (>= n_), so that a join writes
  // its rows in place and a leave moves rows within them.
  Eigen::MatrixXd l_bb_;  // lower triangle of the top-left n x n is L_BB
  Eigen::MatrixXd g_;     // lower triangle of the top-left n x n is G
  Eigen::MatrixXd z_;     // rows 0..n, columns of the cached slots: Z
  Eigen::MatrixXd l_bz_;  // the same for L_Bc
  std::vector<CachedNode> cached_;
  long clock_ = 0;
  int updates_since_check_ = 0;
  Statistics stats_;
};

}  // namespace cohaptic
