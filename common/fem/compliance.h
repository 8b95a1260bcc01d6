// ComplianceColumns: column blocks of the compliance L = K_ff^-1, computed on demand.
//
// L is dense and (3N)^2: never formed. The column block of node j (3 columns, one per
// axis) costs one solve with 3 right-hand sides; only the rows of the `row_nodes` (the
// nodes that can be touched or collide) are kept, in a cache keyed by node. Columns of a
// fixed axis are zero. Units: m/N. L is symmetric: block(i, j) = block(j, i)^T.
#pragma once

#include <Eigen/Core>
#include <span>
#include <unordered_map>
#include <utility>
#include <vector>

#include "common/fem/compliance_source.h"
#include "common/fem/deferred_cholesky.h"
#include "common/fem/dof_map.h"
#include "common/fem/sparse_cholesky.h"

namespace cohaptic {

/// Rows: 3 per row node, in row_nodes order; columns: the node's x, y, z.
using ComplianceColumn = Eigen::Matrix<double, Eigen::Dynamic, 3>;

class ComplianceColumns : public ComplianceSource {
 public:
  /// Row nodes solved together (see compute_columns): 12 right-hand sides per solve. On the
  /// brain (9k free dofs) a solve costs 6.0 ms of CPU for one node, but 10 ms for 4: 2.5 ms
  /// a node, as for 16 or 64 (BM_ComplianceGroupSolve). So 4 solves a surface about as
  /// fast as larger groups, and stalls a step 4 times less than 16 when a node is needed
  /// at once (one that an obstacle starts to hold).
  static constexpr int kGroupSize = 4;

  /// `factor` (a body's K_ff, factored at the first column solved, if any) and `dofs` must
  /// outlive this object; `row_nodes` are volume node indices.
  ComplianceColumns(const DeferredCholesky& factor, const DofMap& dofs, std::vector<int> row_nodes);
  /// The same with a factor already made.
  ComplianceColumns(const SparseCholesky& factor, const DofMap& dofs, std::vector<int> row_nodes)
      : ComplianceColumns(DeferredCholesky::borrowing(factor), dofs, std::move(row_nodes)) {}

  const std::vector<int>& row_nodes() const { return row_nodes_; }
  /// Nodes of the whole volume mesh (the range of column nodes), not the row count.
  int volume_node_count() const { return static_cast<int>(row_position_.size()); }
  /// Position of `node` in row_nodes(), or -1.
  int row_position(int node) const { return row_position_[static_cast<std::size_t>(node)]; }
  bool has_column(int node) const { return columns_.count(node) != 0; }
  std::size_t column_count() const { return columns_.size(); }

  /// L[row_nodes, node], solved on first use.
  const ComplianceColumn& column(int node);
  /// Computes every missing column of `nodes`, in fixed groups of row nodes (so that a
  /// column's bits never depend on what was asked for with it).
  void compute_columns(const std::vector<int>& nodes) override;
  /// L[row_dofs, col_dofs]. Every row dof's node must be a row node; the column nodes'
  /// blocks are computed on demand.
  Eigen::MatrixXd dof_block(std::span<const int> row_dofs, std::span<const int> col_dofs) override;
  /// The 3x3 block L_ij; i must be a row node.
  Eigen::Matrix3d block(int row_node, int column_node);
  /// L_AA (3|A| x 3|A|, symmetrised) for nodes A, all of them row nodes.
  Eigen::MatrixXd gather(const std::vector<int>& nodes);

  /// Cached columns, for persistence. insert_column() checks the row count.
  const std::unordered_map<int, ComplianceColumn>& columns() const { return columns_; }
  void insert_column(int node, ComplianceColumn column);
  /// Moves every cached column out, leaving none (for handing columns solved on one
  /// thread to another's ComplianceColumns).
  std::unordered_map<int, ComplianceColumn> take_columns() { return std::exchange(columns_, {}); }
  /// The solve group of row position `position` (see compute_columns).
  static int group_of(int position) { return position / kGroupSize; }

 private:
  void solve_chunk(std::span<const int> nodes);

  DeferredCholesky factor_;
  CholeskyWorkspace workspace_;  // the solves' scratch: the factor itself stays immutable
  const DofMap& dofs_;
  std::vector<int> row_nodes_;
  std::vector<int> row_position_;  // per volume node
  std::unordered_map<int, ComplianceColumn> columns_;
};

}  // namespace cohaptic
