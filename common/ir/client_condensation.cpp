#include "common/ir/client_condensation.h"

#include <fmt/format.h>

#include <bit>
#include <span>
#include <unordered_set>

#include "common/condense/dof_blocks.h"
#include "common/ir/compliance_rows.h"
#include "common/util/error.h"

namespace cohaptic {
namespace {

int free_axis_count(AxisMask fixed) {
  return 3 - std::popcount(static_cast<unsigned>(fixed & kAllAxes));
}

}  // namespace

// ---- HeldCompliance ----

int HeldCompliance::position_of(int dof) const {
  const int node = dof / 3;
  const int axis = dof % 3;
  if (dof < 0 || static_cast<std::size_t>(node) >= offset_.size() ||
      offset_[static_cast<std::size_t>(node)] < 0)
    throw Error(fmt::format("the compliance of node index {} is not held by this client", node));
  const AxisMask fixed = fixed_[static_cast<std::size_t>(node)];
  if ((fixed >> axis) & 1u)
    throw Error(fmt::format("axis {} of node index {} is fixed: it has no compliance", axis, node));
  const unsigned fixed_before = fixed & ((1u << axis) - 1u);
  return offset_[static_cast<std::size_t>(node)] + axis - std::popcount(fixed_before);
}

void HeldCompliance::compute_columns(const std::vector<int>& nodes) {
  for (const int node : nodes)
    if (node < 0 || static_cast<std::size_t>(node) >= offset_.size() ||
        offset_[static_cast<std::size_t>(node)] < 0)
      throw Error(fmt::format("the compliance of node index {} is not held by this client", node));
}

Eigen::MatrixXd HeldCompliance::dof_block(std::span<const int> row_dofs,
                                          std::span<const int> col_dofs) {
  std::vector<int> rows(row_dofs.size()), cols(col_dofs.size());
  for (std::size_t i = 0; i < row_dofs.size(); ++i) rows[i] = position_of(row_dofs[i]);
  for (std::size_t j = 0; j < col_dofs.size(); ++j) cols[j] = position_of(col_dofs[j]);
  return l_(rows, cols);
}

void HeldCompliance::keep_only(const std::vector<bool>& keep) {
  std::vector<int> kept_nodes, kept_rows;
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    const int node = nodes_[i];
    const int first = offset_[static_cast<std::size_t>(node)];
    offset_[static_cast<std::size_t>(node)] = -1;
    if (!keep[i]) continue;
    offset_[static_cast<std::size_t>(node)] = static_cast<int>(kept_rows.size());
    for (int k = 0; k < free_axis_count(fixed_[static_cast<std::size_t>(node)]); ++k)
      kept_rows.push_back(first + k);
    kept_nodes.push_back(node);
  }
  l_ = l_(kept_rows, kept_rows).eval();
  nodes_ = std::move(kept_nodes);
}

void HeldCompliance::append(const std::vector<int>& added, const Eigen::MatrixXd& rows,
                            const DofMap& dofs) {
  const Eigen::Index old = l_.rows();
  Eigen::Index added_dofs = 0;
  for (const int node : added) {
    if (node < static_cast<int>(offset_.size()) && offset_[static_cast<std::size_t>(node)] >= 0)
      throw Error(fmt::format("node index {} is already held", node));
    added_dofs += free_axis_count(dofs.fixed_axes[static_cast<std::size_t>(node)]);
  }
  if (rows.rows() != added_dofs || rows.cols() != old + added_dofs)
    throw Error(fmt::format("compliance rows are {} x {}, the added nodes need {} x {}",
                            rows.rows(), rows.cols(), added_dofs, old + added_dofs));
  Eigen::Index next = old;
  for (const int node : added) {
    const auto index = static_cast<std::size_t>(node);
    if (index >= offset_.size()) {
      offset_.resize(index + 1, -1);
      fixed_.resize(index + 1, 0);
    }
    fixed_[index] = dofs.fixed_axes[index];
    offset_[index] = static_cast<int>(next);
    next += free_axis_count(fixed_[index]);
    nodes_.push_back(node);
  }
  l_.conservativeResize(next, next);
  l_.bottomRows(added_dofs) = rows;
  l_.topRightCorner(old, added_dofs) = rows.leftCols(old).transpose();
}

void HeldCompliance::clear() {
  nodes_.clear();
  offset_.clear();
  fixed_.clear();
  l_.resize(0, 0);
}

// ---- ClientCondensation ----

ClientCondensation::ClientCondensation()
    : condensation_(std::make_unique<IncrementalCondensation>(held_, dofs_)) {}

int ClientCondensation::index_for(std::int64_t tag, AxisMask fixed,
                                  std::vector<AxisMask>& fixed_axes) {
  int index;
  if (!free_indices_.empty()) {
    index = free_indices_.back();
    free_indices_.pop_back();
    fixed_axes[static_cast<std::size_t>(index)] = fixed;
  } else {
    index = static_cast<int>(fixed_axes.size());
    fixed_axes.push_back(fixed);
  }
  index_of_tag_.emplace(tag, index);
  return index;
}

void ClientCondensation::forget_all() {
  held_.clear();
  held_tags_.clear();
  index_of_tag_.clear();
  free_indices_.clear();
  dofs_ = make_dof_map({});
  condensation_ = std::make_unique<IncrementalCondensation>(held_, dofs_);
  generation_ = 0;
}

void ClientCondensation::complete(CondensedFemIr& ir) {
  if (!ir.compliance_rows) return;
  const ComplianceRows& sent = *ir.compliance_rows;

  // Checks first: an IR that cannot be completed changes nothing.
  const bool fresh = sent.generation == 1;
  if (sent.generation == 0) throw Error("compliance rows of generation 0 (generations start at 1)");
  if (!fresh && sent.generation != generation_ + 1)
    throw Error(
        fmt::format("compliance rows of generation {} extend generation {}, but this client holds "
                    "generation {}: "
                    "refused, an IR was lost or came out of order",
                    sent.generation, sent.generation - 1, generation_));
  // With B truncation the IR holds more nodes than it lists (compliance_rows.h).
  if (ir.truncated_fixed_axes.size() != ir.truncated_node_ids.size())
    throw Error(fmt::format("{} fixed axes for {} truncated held nodes",
                            ir.truncated_fixed_axes.size(), ir.truncated_node_ids.size()));
  const std::vector<std::int64_t> ir_held = ir.held_node_ids();
  std::vector<AxisMask> ir_fixed = ir.fixed_axes;
  ir_fixed.insert(ir_fixed.end(), ir.truncated_fixed_axes.begin(), ir.truncated_fixed_axes.end());
  std::unordered_map<std::int64_t, int> local_of_tag;
  for (std::size_t i = 0; i < ir_held.size(); ++i)
    if (!local_of_tag.emplace(ir_held[i], static_cast<int>(i)).second)
      throw Error(
          fmt::format("node {} is listed twice in the IR{}", ir_held[i],
                      i >= ir.node_ids.size() ? " (among the nodes B truncation leaves out)" : ""));
  const std::vector<std::int64_t> no_nodes;
  const std::vector<std::int64_t>& before = fresh ? no_nodes : held_tags_;
  const std::vector<std::int64_t> after = held_after(before, ir_held);
  Eigen::Index kept_dofs = 0, added_dofs = 0;
  std::size_t kept = 0;
  for (const std::int64_t tag : after) {
    const AxisMask fixed = ir_fixed[static_cast<std::size_t>(local_of_tag.at(tag))];
    const auto held = fresh ? index_of_tag_.end() : index_of_tag_.find(tag);
    if (held != index_of_tag_.end()) {
      if (dofs_.fixed_axes[static_cast<std::size_t>(held->second)] != fixed)
        throw Error(fmt::format(
            "held node {} has other fixed axes in the IR (0x{:x}) than when its rows came (0x{:x})",
            tag, fixed, dofs_.fixed_axes[static_cast<std::size_t>(held->second)]));
      kept_dofs += free_axis_count(fixed);
      ++kept;
    } else {
      added_dofs += free_axis_count(fixed);
    }
  }
  if (sent.rows.rows() != added_dofs || sent.rows.cols() != kept_dofs + added_dofs)
    throw Error(
        fmt::format("compliance rows of generation {} are {} x {}; the {} added nodes need {} x {}",
                    sent.generation, sent.rows.rows(), sent.rows.cols(), after.size() - kept,
                    added_dofs, kept_dofs + added_dofs));
  if (!sent.rows.allFinite())
    throw Error(
        fmt::format("compliance rows of generation {} are not all finite", sent.generation));

  // The held set follows the server's: forget what left, append what came.
  if (fresh) forget_all();
  std::vector<bool> keep(held_tags_.size());
  for (std::size_t i = 0; i < held_tags_.size(); ++i) {
    keep[i] = local_of_tag.contains(held_tags_[i]);
    if (keep[i]) continue;
    const int index = index_of_tag_.at(held_tags_[i]);
    condensation_->forget_node(index);
    index_of_tag_.erase(held_tags_[i]);
    free_indices_.push_back(index);
  }
  held_.keep_only(keep);
  std::vector<int> added;
  std::vector<AxisMask> fixed_axes = dofs_.fixed_axes;
  for (std::size_t i = kept; i < after.size(); ++i)
    added.push_back(index_for(
        after[i], ir_fixed[static_cast<std::size_t>(local_of_tag.at(after[i]))], fixed_axes));
  dofs_ = make_dof_map(std::move(fixed_axes));  // in place: the condensation holds a reference
  held_.append(added, sent.rows, dofs_);
  held_tags_ = after;
  generation_ = sent.generation;

  // M~ for the IR's contact nodes with all its held nodes as B (the truncated ones last),
  // in the IR's columns: the truncated nodes' columns of M_CB are dropped.
  std::vector<int> contact, boundary;
  for (std::size_t i = 0; i < ir_held.size(); ++i)
    (i < static_cast<std::size_t>(ir.row_node_count) ? contact : boundary)
        .push_back(index_of_tag_.at(ir_held[i]));
  CondensedOperator op;
  try {
    condensation_->set_boundary_nodes(boundary);
    op = condensation_->condense(contact);
  } catch (const Error&) {
    // The held rows still follow the server's; only the factor starts afresh.
    condensation_ = std::make_unique<IncrementalCondensation>(held_, dofs_);
    throw;
  }
  const auto listed_boundary = std::span<const int>(boundary).first(
      ir.node_ids.size() - static_cast<std::size_t>(ir.row_node_count));
  const std::vector<int> boundary_dofs = free_dofs_of_nodes(dofs_, listed_boundary);
  std::unordered_map<int, Eigen::Index> column_of_dof;
  const Eigen::Index c = op.m_cc.rows();
  for (std::size_t k = 0; k < boundary_dofs.size(); ++k)
    column_of_dof.emplace(boundary_dofs[k], c + static_cast<Eigen::Index>(k));
  ir.m_tilde.resize(c, c + static_cast<Eigen::Index>(boundary_dofs.size()));
  ir.m_tilde.leftCols(c) = op.m_cc;
  for (std::size_t k = 0; k < op.boundary_dofs.size(); ++k)
    if (const auto column = column_of_dof.find(op.boundary_dofs[k]); column != column_of_dof.end())
      ir.m_tilde.col(column->second) = op.m_cb.col(static_cast<Eigen::Index>(k));
  ir.compliance_rows.reset();
  ir.truncated_node_ids.clear();
  ir.truncated_fixed_axes.clear();
}

}  // namespace cohaptic
