#include "common/condense/incremental_condensation.h"

#include <Eigen/Cholesky>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "common/condense/dense_kernels.h"
#include "common/condense/dof_blocks.h"
#include "common/condense/naive_condensation.h"
#include "common/util/error.h"
#include "common/util/stopwatch.h"

namespace cohaptic {
namespace {

// Deletes rows [first, first + count) from the leading `rows` rows of columns [0, cols)
// of `buffer`, moving the rows below up, in place.
void remove_rows(Eigen::MatrixXd& buffer, int rows, Eigen::Index cols, int first, int count) {
  const auto moved = static_cast<std::size_t>(rows - first - count);
  for (Eigen::Index col = 0; col < cols; ++col) {
    double* column = buffer.data() + col * buffer.rows();
    std::memmove(column + first, column + first + count, sizeof(double) * moved);
  }
}

// Deletes rows and columns [first, first + count) from the lower triangle of the leading
// size x size block of `buffer`, in place; only the lower triangle is moved.
void remove_from_lower_triangle(Eigen::MatrixXd& buffer, int size, int first, int count) {
  remove_rows(buffer, size, first, first, count);
  const Eigen::Index stride = buffer.rows();
  for (int col = first + count; col < size; ++col)
    std::memmove(buffer.data() + (col - count) * stride + (col - count),
                 buffer.data() + col * stride + col,
                 sizeof(double) * static_cast<std::size_t>(size - col));
}

// Frobenius norm of the symmetric matrix whose lower triangle `lower` holds.
double symmetric_frobenius_norm(const Eigen::Ref<const Eigen::MatrixXd>& lower) {
  double squared = 0;
  for (Eigen::Index j = 0; j < lower.cols(); ++j)
    squared +=
        lower(j, j) * lower(j, j) + 2 * lower.col(j).tail(lower.rows() - j - 1).squaredNorm();
  return std::sqrt(squared);
}

}  // namespace

IncrementalCondensation::IncrementalCondensation(ComplianceSource& columns, const DofMap& dofs,
                                                 Options options)
    : columns_(&columns), dofs_(dofs), options_(options) {}

bool IncrementalCondensation::in_boundary(int node) const {
  return std::find(b_nodes_.begin(), b_nodes_.end(), node) != b_nodes_.end();
}

void IncrementalCondensation::ensure_row_capacity(int rows) {
  if (rows <= g_.rows()) return;
  // A quarter more each time: amortised O(n) per dof added, and at |B| = 1000 about 110 MB
  // per buffer instead of the 290 MB of doubling.
  const Eigen::Index capacity = std::max<Eigen::Index>(rows, g_.rows() + g_.rows() / 4 + 12);
  l_bb_.conservativeResize(capacity, capacity);
  g_.conservativeResize(capacity, capacity);
  z_.conservativeResize(capacity, z_.cols());
  l_bz_.conservativeResize(capacity, l_bz_.cols());
}

void IncrementalCondensation::ensure_slot_capacity(std::size_t slots) {
  const auto columns = 3 * static_cast<Eigen::Index>(slots);
  if (columns <= z_.cols()) return;
  const Eigen::Index capacity = std::max(columns, 2 * z_.cols());
  z_.conservativeResize(g_.rows(), capacity);
  l_bz_.conservativeResize(g_.rows(), capacity);
}

int IncrementalCondensation::slot_of(int node) const {
  for (std::size_t s = 0; s < cached_.size(); ++s)
    if (cached_[s].node == node) return static_cast<int>(s);
  return -1;
}

Eigen::MatrixXd IncrementalCondensation::column_rows_at_boundary(int node) {
  return gather_compliance(*columns_, b_dofs_,
                           free_dofs_of_nodes(dofs_, std::span<const int>(&node, 1)));
}

Eigen::MatrixXd IncrementalCondensation::compliance_to_slots(std::span<const int> row_dofs,
                                                             std::size_t first_slot) {
  std::vector<int> dofs;
  std::vector<Eigen::Index> column_of;
  for (std::size_t s = first_slot; s < cached_.size(); ++s) {
    const std::vector<int> node_dofs =
        free_dofs_of_nodes(dofs_, std::span<const int>(&cached_[s].node, 1));
    for (std::size_t axis = 0; axis < node_dofs.size(); ++axis) {
      dofs.push_back(node_dofs[axis]);
      column_of.push_back(3 * static_cast<Eigen::Index>(s - first_slot) +
                          static_cast<Eigen::Index>(axis));
    }
  }
  const Eigen::MatrixXd gathered = gather_compliance(*columns_, row_dofs, dofs);
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(
      gathered.rows(), 3 * static_cast<Eigen::Index>(cached_.size() - first_slot));
  for (std::size_t j = 0; j < column_of.size(); ++j)
    out.col(column_of[j]) = gathered.col(static_cast<Eigen::Index>(j));
  return out;
}

void IncrementalCondensation::add_boundary_node(int node) {
  if (in_boundary(node)) throw Error(fmt::format("node {} is already a boundary node", node));
  const std::vector<int> new_dofs = free_dofs_of_nodes(dofs_, std::span<const int>(&node, 1));
  const auto k = static_cast<int>(new_dofs.size());
  if (k == 0) return;  // a fully fixed node carries no unknown: nothing to hold

  Stopwatch watch;
  const int n = n_;
  const Eigen::MatrixXd l = column_rows_at_boundary(node);                    // n x k
  Eigen::MatrixXd lambda = gather_compliance(*columns_, new_dofs, new_dofs);  // k x k
  lambda = 0.5 * (lambda + lambda.transpose()).eval();
  ensure_row_capacity(n + k);
  const auto g_old = g_.topLeftCorner(n, n);
  // The new rows of G: [G 0; g^T rho] with g = G^-1 l and rho rho^T = lambda - g^T g.
  Eigen::MatrixXd g = l;
  solve_lower_in_place(g_old, g);
  const Eigen::LLT<Eigen::MatrixXd> rho(lambda - g.transpose() * g);
  if (rho.info() != Eigen::Success)
    throw NumericalError(fmt::format(
        "node {} cannot join the boundary set: L_BB would not be positive definite (the node "
        "duplicates "
        "others, or the set is numerically singular; condition estimate of L_BB {:.3g})",
        node, n > 0 ? cholesky_condition_estimate(g_old) : 1.0));
  const Eigen::MatrixXd rho_lower = rho.matrixL();
  stats_.factor_ms += watch.lap_ms();

  if (!cached_.empty()) {
    update_cached_z_for_join(new_dofs, l, g, rho_lower);
    stats_.z_ms += watch.lap_ms();
  }

  g_.block(n, 0, k, n) = g.transpose();
  g_.block(n, n, k, k) = rho_lower;
  l_bb_.block(n, 0, k, n) = l.transpose();
  l_bb_.block(n, n, k, k) = lambda;
  b_node_offset_.push_back(n);
  b_nodes_.push_back(node);
  b_dofs_.insert(b_dofs_.end(), new_dofs.begin(), new_dofs.end());
  n_ = n + k;
  ++stats_.joins;
  stats_.factor_ms += watch.lap_ms();
  after_update();
}

void IncrementalCondensation::update_cached_z_for_join(std::span<const int> new_dofs,
                                                       const Eigen::MatrixXd& l,
                                                       const Eigen::MatrixXd& g,
                                                       const Eigen::MatrixXd& rho_lower) {
  // Z' = [Z - q t; t] with q = L_BB^-1 l and t = (rho rho^T)^-1 (L_bc - l^T Z).
  const int n = n_;
  const auto k = static_cast<Eigen::Index>(new_dofs.size());
  const Eigen::Index columns = cached_columns();
  Eigen::MatrixXd q = g;
  solve_lower_transposed_in_place(g_.topLeftCorner(n, n), q);
  Eigen::MatrixXd t = compliance_to_slots(new_dofs, 0);
  l_bz_.block(n, 0, k, columns) = t;
  auto z = z_.block(0, 0, n, columns);
  multiply(-1, l, Transposed::yes, z, Transposed::no, 1, t);
  solve_lower_in_place(rho_lower, t);
  solve_lower_transposed_in_place(rho_lower, t);
  multiply(-1, q, Transposed::no, t, Transposed::no, 1, z);
  z_.block(n, 0, k, columns) = t;
}

void IncrementalCondensation::remove_boundary_node(int node) {
  const auto it = std::find(b_nodes_.begin(), b_nodes_.end(), node);
  if (it == b_nodes_.end()) throw Error(fmt::format("node {} is not a boundary node", node));
  const auto position = static_cast<std::size_t>(it - b_nodes_.begin());
  const int first = b_node_offset_[position];
  const int k = (position + 1 < b_nodes_.size() ? b_node_offset_[position + 1] : n_) - first;
  const int n = n_;
  const int below = n - first - k;

  Stopwatch watch;
  if (!cached_.empty()) {
    update_cached_z_for_leave(first, k);
    stats_.z_ms += watch.lap_ms();
  }
  // G without the node: the block below it absorbs the rows dropped from under the node,
  // G33' G33'^T = G33 G33^T + G32 G32^T, written straight to its place k rows and columns
  // up; the columns before the node only lose k rows.
  if (below > 0) {
    Eigen::MatrixXd dropped = g_.block(first + k, first, below, k);
    cholesky_rank_update(g_.block(first + k, first + k, below, below), dropped,
                         g_.block(first, first, below, below));
  }
  remove_rows(g_, n, first, first, k);
  remove_from_lower_triangle(l_bb_, n, first, k);

  b_dofs_.erase(b_dofs_.begin() + first, b_dofs_.begin() + first + k);
  b_nodes_.erase(it);
  b_node_offset_.erase(b_node_offset_.begin() + static_cast<std::ptrdiff_t>(position));
  for (std::size_t i = position; i < b_node_offset_.size(); ++i) b_node_offset_[i] -= k;
  n_ = n - k;
  ++stats_.leaves;
  stats_.factor_ms += watch.lap_ms();
  after_update();
}

void IncrementalCondensation::update_cached_z_for_leave(int first, int k) {
  // With N = L_BB^-1 restricted to the node's columns, Z_a' = Z_a - N_a N_bb^-1 Z_b.
  const int n = n_;
  const int below = n - first - k;
  const Eigen::Index columns = cached_columns();
  Eigen::MatrixXd inverse_columns = Eigen::MatrixXd::Zero(n, k);
  inverse_columns.middleRows(first, k).setIdentity();
  // G^-1 E_b is zero above the node's rows: the forward solve starts there.
  solve_lower_in_place(g_.block(first, first, n - first, n - first),
                       inverse_columns.bottomRows(n - first));
  solve_lower_transposed_in_place(g_.topLeftCorner(n, n), inverse_columns);
  const Eigen::LLT<Eigen::MatrixXd> n_bb(inverse_columns.middleRows(first, k));
  if (n_bb.info() != Eigen::Success)
    throw NumericalError(
        fmt::format("boundary node at dof {} cannot leave: L_BB^-1 has lost positive definiteness "
                    "({} boundary dofs)",
                    first, n));
  const Eigen::MatrixXd h = n_bb.solve(z_.block(first, 0, k, columns));
  multiply(-1, inverse_columns.topRows(first), Transposed::no, h, Transposed::no, 1,
           z_.block(0, 0, first, columns));
  multiply(-1, inverse_columns.bottomRows(below), Transposed::no, h, Transposed::no, 1,
           z_.block(first + k, 0, below, columns));
  remove_rows(z_, n, columns, first, k);
  remove_rows(l_bz_, n, columns, first, k);
}

void IncrementalCondensation::set_boundary_nodes(std::span<const int> nodes) {
  const std::vector<int> current = b_nodes_;
  for (int node : current)
    if (std::find(nodes.begin(), nodes.end(), node) == nodes.end()) remove_boundary_node(node);
  std::vector<int> joining;
  for (int node : nodes)
    if (!in_boundary(node) && std::find(joining.begin(), joining.end(), node) == joining.end())
      joining.push_back(node);
  columns_->compute_columns(joining);  // one multi-right-hand-side solve for them all
  // Many at once (a step-delay set): append them to L_BB and factor once, O(|B|^3 / 3),
  // cheaper than as many bordering steps.
  if (joining.size() <= kBulkJoin) {
    for (int node : joining) add_boundary_node(node);
    return;
  }
  Stopwatch watch;
  std::vector<int> new_dofs;
  for (int node : joining) {
    const std::vector<int> node_dofs = free_dofs_of_nodes(dofs_, std::span<const int>(&node, 1));
    if (node_dofs.empty()) continue;
    b_node_offset_.push_back(n_ + static_cast<int>(new_dofs.size()));
    b_nodes_.push_back(node);
    new_dofs.insert(new_dofs.end(), node_dofs.begin(), node_dofs.end());
  }
  const auto k = static_cast<int>(new_dofs.size());
  ensure_row_capacity(n_ + k);
  const Eigen::MatrixXd l_new = gather_compliance(*columns_, b_dofs_, new_dofs);
  const Eigen::MatrixXd lambda = gather_compliance(*columns_, new_dofs, new_dofs);
  l_bb_.block(n_, 0, k, n_) = l_new.transpose();
  l_bb_.block(n_, n_, k, k) = 0.5 * (lambda + lambda.transpose());
  b_dofs_.insert(b_dofs_.end(), new_dofs.begin(), new_dofs.end());
  n_ += k;
  stats_.joins += static_cast<long>(joining.size());
  factor_from_scratch(
      "the boundary nodes cannot be held together: L_BB is not positive definite (duplicate nodes, "
      "or a numerically "
      "singular set)");
  stats_.factor_ms += watch.lap_ms();
}

void IncrementalCondensation::compute_z(std::span<const int> nodes) {
  const std::size_t first_new = cached_.size();
  for (int node : nodes)
    if (slot_of(node) < 0)
      cached_.push_back(
          {node, static_cast<int>(free_dofs_of_nodes(dofs_, std::span<const int>(&node, 1)).size()),
           clock_});
  if (cached_.size() == first_new) return;
  ensure_slot_capacity(cached_.size());
  const auto first_column = 3 * static_cast<Eigen::Index>(first_new);
  const Eigen::Index columns = cached_columns() - first_column;
  l_bz_.block(0, first_column, n_, columns) = compliance_to_slots(b_dofs_, first_new);
  auto z = z_.block(0, first_column, n_, columns);
  z = l_bz_.block(0, first_column, n_, columns);
  solve_lower_in_place(g_.topLeftCorner(n_, n_), z);
  solve_lower_transposed_in_place(g_.topLeftCorner(n_, n_), z);
}

CondensedOperator IncrementalCondensation::condense(std::span<const int> contact_nodes) {
  ++clock_;
  for (int node : contact_nodes)
    if (in_boundary(node))
      throw Error(fmt::format("node {} is both a contact and a boundary node", node));
  if (options_.naive) return naive_condensation(*columns_, dofs_, contact_nodes, b_nodes_);
  Stopwatch watch;
  compute_z(contact_nodes);
  stats_.z_ms += watch.lap_ms();

  CondensedOperator op;
  op.contact_dofs = free_dofs_of_nodes(dofs_, contact_nodes);
  op.boundary_dofs = b_dofs_;
  const auto m = static_cast<Eigen::Index>(op.contact_dofs.size());
  Eigen::MatrixXd z_c(n_, m), l_bc(n_, m);
  Eigen::Index col = 0;
  for (int node : contact_nodes) {
    const int slot = slot_of(node);
    CachedNode& cached = cached_[static_cast<std::size_t>(slot)];
    cached.last_used = clock_;
    z_c.middleCols(col, cached.width) = z_.block(0, 3 * slot, n_, cached.width);
    l_bc.middleCols(col, cached.width) = l_bz_.block(0, 3 * slot, n_, cached.width);
    col += cached.width;
  }
  Eigen::MatrixXd s = gather_compliance(*columns_, op.contact_dofs, op.contact_dofs);
  multiply(-1, l_bc, Transposed::yes, z_c, Transposed::no, 1, s);
  s = 0.5 * (s + s.transpose()).eval();
  const Eigen::LLT<Eigen::MatrixXd> llt(s);
  if (llt.info() != Eigen::Success)
    throw NumericalError(
        fmt::format("the condensed compliance of {} contact dofs (with {} boundary dofs held) is "
                    "not positive definite",
                    m, n_));
  op.condition_estimate = cholesky_condition_estimate(llt.matrixL());
  op.m_cc = llt.solve(Eigen::MatrixXd::Identity(m, m));
  op.m_cc = 0.5 * (op.m_cc + op.m_cc.transpose()).eval();
  stats_.schur_ms += watch.lap_ms();
  op.m_cb.resize(m, n_);
  multiply(-1, op.m_cc, Transposed::no, z_c, Transposed::yes, 0, op.m_cb);
  stats_.m_cb_ms += watch.lap_ms();
  forget_least_recently_used();
  return op;
}

void IncrementalCondensation::forget_least_recently_used() {
  // Keep the cache bounded: the last slot fills the one freed, so slots stay contiguous.
  while (cached_.size() > options_.z_cache_nodes) {
    const auto oldest = std::min_element(
        cached_.begin(), cached_.end(),
        [](const CachedNode& a, const CachedNode& b) { return a.last_used < b.last_used; });
    if (oldest->last_used == clock_) break;
    drop_slot(static_cast<std::size_t>(oldest - cached_.begin()));
  }
}

void IncrementalCondensation::drop_slot(std::size_t slot) {
  const std::size_t last = cached_.size() - 1;
  if (slot != last) {
    z_.block(0, 3 * static_cast<Eigen::Index>(slot), n_, 3) =
        z_.block(0, 3 * static_cast<Eigen::Index>(last), n_, 3);
    l_bz_.block(0, 3 * static_cast<Eigen::Index>(slot), n_, 3) =
        l_bz_.block(0, 3 * static_cast<Eigen::Index>(last), n_, 3);
    cached_[slot] = cached_.back();
  }
  cached_.pop_back();
}

void IncrementalCondensation::forget_node(int node) {
  if (in_boundary(node)) remove_boundary_node(node);
  if (const int slot = slot_of(node); slot >= 0) drop_slot(static_cast<std::size_t>(slot));
}

Eigen::MatrixXd IncrementalCondensation::solve_boundary(const Eigen::MatrixXd& rhs) const {
  if (rhs.rows() != n_)
    throw Error(fmt::format("solve_boundary: {} rows for {} boundary dofs", rhs.rows(), n_));
  Eigen::MatrixXd x = rhs;
  solve_lower_in_place(g_.topLeftCorner(n_, n_), x);
  solve_lower_transposed_in_place(g_.topLeftCorner(n_, n_), x);
  return x;
}

void IncrementalCondensation::after_update() {
  if (++updates_since_check_ < options_.check_interval) return;
  updates_since_check_ = 0;
  Stopwatch watch;
  if (check_residuals() > options_.drift_tolerance) refactor();
  stats_.factor_ms += watch.elapsed_ms();
}

double IncrementalCondensation::check_residuals() {
  ++stats_.residual_checks;
  double worst = 0;
  if (n_ > 0) {
    const auto l = l_bb_.topLeftCorner(n_, n_);
    const auto g = g_.topLeftCorner(n_, n_);
    const double l_norm = symmetric_frobenius_norm(l);
    // A deterministic probe vector: the factor must reproduce L_BB on it.
    Eigen::VectorXd x(n_);
    for (int i = 0; i < n_; ++i)
      x[i] = std::sin(1.0 + 0.7 * i + 0.013 * static_cast<double>(stats_.residual_checks));
    const Eigen::VectorXd gx = g.triangularView<Eigen::Lower>().transpose() * x;
    const Eigen::VectorXd ggx = g.triangularView<Eigen::Lower>() * gx;
    const Eigen::VectorXd lx = l.selfadjointView<Eigen::Lower>() * x;
    worst = (ggx - lx).norm() / (l_norm * x.norm());
    // And one cached Z, in turn: L_BB Z_c must equal L_Bc.
    if (!cached_.empty()) {
      const auto slot = static_cast<std::size_t>(stats_.residual_checks) % cached_.size();
      const CachedNode& cached = cached_[slot];
      const Eigen::MatrixXd l_bc = column_rows_at_boundary(cached.node);
      const auto z = z_.block(0, 3 * static_cast<Eigen::Index>(slot), n_, cached.width);
      const Eigen::MatrixXd lz = l.selfadjointView<Eigen::Lower>() * z;
      worst = std::max(worst, (lz - l_bc).norm() / (l_norm * z.norm() + l_bc.norm()));
    }
  }
  stats_.last_residual = worst;
  return worst;
}

void IncrementalCondensation::refactor() {
  ++stats_.refactorizations;
  factor_from_scratch("L_BB is no longer positive definite");
}

void IncrementalCondensation::factor_from_scratch(const char* failure) {
  if (n_ > 0) {
    Eigen::Ref<Eigen::MatrixXd> g = g_.topLeftCorner(n_, n_);
    g.triangularView<Eigen::Lower>() = l_bb_.topLeftCorner(n_, n_);
    const Eigen::LLT<Eigen::Ref<Eigen::MatrixXd>, Eigen::Lower> llt(g);  // in place, lower triangle
    if (llt.info() != Eigen::Success)
      throw NumericalError(fmt::format("{} ({} boundary dofs)", failure, n_));
  }
  // Every cached Z again, from the compliance itself.
  if (cached_.empty()) return;
  const Eigen::Index columns = cached_columns();
  l_bz_.block(0, 0, n_, columns) = compliance_to_slots(b_dofs_, 0);
  auto z = z_.block(0, 0, n_, columns);
  z = l_bz_.block(0, 0, n_, columns);
  solve_lower_in_place(g_.topLeftCorner(n_, n_), z);
  solve_lower_transposed_in_place(g_.topLeftCorner(n_, n_), z);
}

}  // namespace cohaptic
