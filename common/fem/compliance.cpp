#include "common/fem/compliance.h"

#include <fmt/format.h>

#include <algorithm>

#include "common/util/error.h"

namespace cohaptic {

ComplianceColumns::ComplianceColumns(const DeferredCholesky& factor, const DofMap& dofs,
                                     std::vector<int> row_nodes)
    : factor_(factor),
      dofs_(dofs),
      row_nodes_(std::move(row_nodes)),
      row_position_(static_cast<std::size_t>(dofs.node_count()), -1) {
  for (int i = 0; i < static_cast<int>(row_nodes_.size()); ++i) {
    const int node = row_nodes_[i];
    if (node < 0 || node >= dofs.node_count())
      throw Error(fmt::format("compliance: row node {} out of range", node));
    if (row_position_[node] >= 0)
      throw Error(fmt::format("compliance: row node {} listed twice", node));
    row_position_[node] = i;
  }
}

const ComplianceColumn& ComplianceColumns::column(int node) {
  if (!has_column(node)) compute_columns({node});
  return columns_.at(node);
}

void ComplianceColumns::compute_columns(const std::vector<int>& nodes) {
  // Columns are solved in fixed groups of kGroupSize consecutive row nodes, always the
  // whole group in one solve: the numbers of a column then never depend on which other
  // columns were asked for with it (a solve's rounding depends on its right-hand sides'
  // count), so a replayed session rebuilds the same M~ bit for bit. A node that is not a
  // row node is solved alone.
  std::vector<int> groups, singles;
  for (int node : nodes) {
    if (node < 0 || node >= dofs_.node_count())
      throw Error(fmt::format("compliance: node {} out of range", node));
    if (has_column(node)) continue;
    const int position = row_position(node);
    std::vector<int>& list = position >= 0 ? groups : singles;
    const int key = position >= 0 ? group_of(position) : node;
    if (std::find(list.begin(), list.end(), key) == list.end()) list.push_back(key);
  }
  std::sort(groups.begin(), groups.end());
  for (int group : groups) {
    const std::size_t first = static_cast<std::size_t>(group) * kGroupSize;
    const std::size_t count = std::min<std::size_t>(kGroupSize, row_nodes_.size() - first);
    solve_chunk(std::span<const int>(row_nodes_).subspan(first, count));
  }
  for (int node : singles) solve_chunk(std::span<const int>(&node, 1));
}

void ComplianceColumns::solve_chunk(std::span<const int> nodes) {
  // One right-hand side per axis of every node: a unit force on that dof.
  const auto count = static_cast<Eigen::Index>(nodes.size());
  const SparseCholesky& factor = factor_.factor();
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(factor.size(), 3 * count);
  for (Eigen::Index k = 0; k < count; ++k)
    for (int axis = 0; axis < 3; ++axis) {
      const int free = dofs_.free_index[3 * nodes[k] + axis];
      if (free >= 0) rhs(free, 3 * k + axis) = 1.0;
    }
  const Eigen::MatrixXd solution = factor.solve(rhs, workspace_);
  const auto rows = static_cast<Eigen::Index>(3 * row_nodes_.size());
  for (Eigen::Index k = 0; k < count; ++k) {
    ComplianceColumn column = ComplianceColumn::Zero(rows, 3);
    for (int r = 0; r < static_cast<int>(row_nodes_.size()); ++r)
      for (int axis = 0; axis < 3; ++axis) {
        const int free = dofs_.free_index[3 * row_nodes_[r] + axis];
        if (free >= 0) column.row(3 * r + axis) = solution.block(free, 3 * k, 1, 3);
      }
    // A fixed axis of the column node carries no force: its column stays zero.
    for (int axis = 0; axis < 3; ++axis)
      if (dofs_.is_fixed(nodes[k], axis)) column.col(axis).setZero();
    columns_.try_emplace(nodes[k], std::move(column));  // a group may hold columns already known
  }
}

Eigen::Matrix3d ComplianceColumns::block(int row_node, int column_node) {
  const int position = row_position(row_node);
  if (position < 0) throw Error(fmt::format("compliance: node {} is not a row node", row_node));
  return column(column_node).middleRows<3>(3 * position);
}

Eigen::MatrixXd ComplianceColumns::gather(const std::vector<int>& nodes) {
  compute_columns(nodes);
  const auto n = static_cast<Eigen::Index>(nodes.size());
  Eigen::MatrixXd l(3 * n, 3 * n);
  for (Eigen::Index j = 0; j < n; ++j) {
    const ComplianceColumn& col = columns_.at(nodes[j]);
    for (Eigen::Index i = 0; i < n; ++i) {
      const int position = row_position(nodes[i]);
      if (position < 0) throw Error(fmt::format("compliance: node {} is not a row node", nodes[i]));
      l.block<3, 3>(3 * i, 3 * j) = col.middleRows<3>(3 * position);
    }
  }
  // Solves are symmetric only to round-off; M = L^-1 must be exactly symmetric.
  return 0.5 * (l + l.transpose());
}

void ComplianceColumns::insert_column(int node, ComplianceColumn column) {
  if (column.rows() != static_cast<Eigen::Index>(3 * row_nodes_.size()))
    throw Error(fmt::format("compliance: column for node {} has {} rows, expected {}", node,
                            column.rows(), 3 * row_nodes_.size()));
  columns_[node] = std::move(column);
}

Eigen::MatrixXd ComplianceColumns::dof_block(std::span<const int> row_dofs,
                                             std::span<const int> col_dofs) {
  std::vector<int> row_index(row_dofs.size());
  for (std::size_t i = 0; i < row_dofs.size(); ++i) {
    const int position = row_position(row_dofs[i] / 3);
    if (position < 0)
      throw Error(
          fmt::format("compliance rows are not kept for node {} (not touchable or on the surface)",
                      row_dofs[i] / 3));
    row_index[i] = 3 * position + row_dofs[i] % 3;
  }
  // Missing columns are solved on first use, in their fixed groups (see compute_columns).
  Eigen::MatrixXd block(static_cast<Eigen::Index>(row_dofs.size()),
                        static_cast<Eigen::Index>(col_dofs.size()));
  for (std::size_t j = 0; j < col_dofs.size(); ++j) {
    const ComplianceColumn& node_column = column(col_dofs[j] / 3);
    const int axis = col_dofs[j] % 3;
    for (std::size_t i = 0; i < row_dofs.size(); ++i)
      block(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) =
          node_column(row_index[i], axis);
  }
  return block;
}

}  // namespace cohaptic
