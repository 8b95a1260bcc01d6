#include "common/condense/incremental_condensation.h"

#include <Eigen/Cholesky>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "common/condense/dof_blocks.h"
#include "common/condense/naive_condensation.h"
#include "common/util/error.h"

namespace cohaptic {
namespace {

// Removes rows and columns [first, first + count) from the leading size x size block of
// `buffer`, shifting the rest up and left in place.
void remove_rows_and_columns(Eigen::MatrixXd& buffer, int size, int first, int count) {
  const Eigen::Index stride = buffer.rows();
  double* data = buffer.data();
  for (int col = first + count; col < size; ++col)
    std::memmove(data + (col - count) * stride, data + col * stride, sizeof(double) * static_cast<std::size_t>(size));
  for (int col = 0; col < size - count; ++col) {
    double* column = data + col * stride;
    std::memmove(column + first, column + first + count, sizeof(double) * static_cast<std::size_t>(size - first - count));
  }
}

// R^T R + v v^T for upper triangular R (m x m), in place; v is overwritten.
template <typename Block>
void cholesky_rank_one_update(Block r, Eigen::VectorXd& v) {
  const Eigen::Index m = r.rows();
  for (Eigen::Index j = 0; j < m; ++j) {
    const double rjj = r(j, j);
    const double radius = std::hypot(rjj, v[j]);
    const double c = radius / rjj, s = v[j] / rjj;
    r(j, j) = radius;
    if (j + 1 < m) {
      const Eigen::Index rest = m - j - 1;
      r.row(j).tail(rest) = (r.row(j).tail(rest) + s * v.tail(rest).transpose()) / c;
      v.tail(rest) = c * v.tail(rest) - s * r.row(j).tail(rest).transpose();
    }
  }
}

}  // namespace

IncrementalCondensation::IncrementalCondensation(ComplianceColumns& columns, const DofMap& dofs, Options options)
    : columns_(columns), dofs_(dofs), options_(options) {}

bool IncrementalCondensation::in_boundary(int node) const {
  return std::find(b_nodes_.begin(), b_nodes_.end(), node) != b_nodes_.end();
}

void IncrementalCondensation::ensure_capacity(int size) {
  if (size <= l_bb_.rows()) return;
  const Eigen::Index capacity = std::max<Eigen::Index>(size, 2 * l_bb_.rows() + 12);
  l_bb_.conservativeResize(capacity, capacity);
  r_.conservativeResize(capacity, capacity);
}

Eigen::MatrixXd IncrementalCondensation::column_rows_at_boundary(int node) {
  return gather_compliance(columns_, b_dofs_, free_dofs_of_nodes(dofs_, std::span<const int>(&node, 1)));
}

void IncrementalCondensation::add_boundary_node(int node) {
  if (in_boundary(node)) throw Error(fmt::format("node {} is already a boundary node", node));
  const std::vector<int> new_dofs = free_dofs_of_nodes(dofs_, std::span<const int>(&node, 1));
  const auto k = static_cast<int>(new_dofs.size());
  if (k == 0) return;  // a fully fixed node carries no unknown: nothing to hold

  const Eigen::MatrixXd l = column_rows_at_boundary(node);                      // n x k
  Eigen::MatrixXd lambda = gather_compliance(columns_, new_dofs, new_dofs);     // k x k
  lambda = 0.5 * (lambda + lambda.transpose()).eval();
  const auto n = n_;
  auto r_old = r_.topLeftCorner(n, n);
  const Eigen::MatrixXd r_col = n > 0 ? Eigen::MatrixXd(r_old.triangularView<Eigen::Upper>().transpose().solve(l))
                                      : Eigen::MatrixXd(0, k);
  const Eigen::MatrixXd schur = lambda - r_col.transpose() * r_col;
  const Eigen::LLT<Eigen::MatrixXd> rho(schur);
  if (rho.info() != Eigen::Success)
    throw NumericalError(fmt::format(
        "node {} cannot join the boundary set: L_BB would not be positive definite (the node duplicates "
        "others, or the set is numerically singular; condition estimate of L_BB {:.3g})",
        node, n > 0 ? cholesky_condition_estimate(r_old) : 1.0));
  const Eigen::MatrixXd q = n > 0 ? Eigen::MatrixXd(r_old.triangularView<Eigen::Upper>().solve(r_col))
                                  : Eigen::MatrixXd(0, k);

  // Z_c for cached contact nodes: [Z - q t; t] with t = S^-1 (L_bc - l^T Z).
  for (auto& [c, cached] : z_) {
    const std::vector<int> c_dofs = free_dofs_of_nodes(dofs_, std::span<const int>(&c, 1));
    const Eigen::MatrixXd l_bc = gather_compliance(columns_, new_dofs, c_dofs);
    const Eigen::MatrixXd t = rho.solve(l_bc - l.transpose() * cached.z);
    Eigen::MatrixXd z(n + k, cached.z.cols());
    z.topRows(n) = cached.z - q * t;
    z.bottomRows(k) = t;
    cached.z = std::move(z);
  }

  ensure_capacity(n + k);
  l_bb_.block(0, n, n, k) = l;
  l_bb_.block(n, 0, k, n) = l.transpose();
  l_bb_.block(n, n, k, k) = lambda;
  r_.block(0, n, n, k) = r_col;
  r_.block(n, 0, k, n).setZero();
  r_.block(n, n, k, k) = rho.matrixU();
  b_node_offset_.push_back(n);
  b_nodes_.push_back(node);
  b_dofs_.insert(b_dofs_.end(), new_dofs.begin(), new_dofs.end());
  n_ = n + k;
  ++stats_.joins;
  after_update();
}

void IncrementalCondensation::remove_boundary_node(int node) {
  const auto it = std::find(b_nodes_.begin(), b_nodes_.end(), node);
  if (it == b_nodes_.end()) throw Error(fmt::format("node {} is not a boundary node", node));
  const auto position = static_cast<std::size_t>(it - b_nodes_.begin());
  const int first = b_node_offset_[position];
  const int k = (position + 1 < b_nodes_.size() ? b_node_offset_[position + 1] : n_) - first;
  const int n = n_;
  auto r = r_.topLeftCorner(n, n);

  // The node's columns of L_BB^-1: N_ab and N_bb; then Z_c <- Z_a - N_ab N_bb^-1 Z_b.
  Eigen::MatrixXd unit = Eigen::MatrixXd::Zero(n, k);
  unit.middleRows(first, k).setIdentity();
  Eigen::MatrixXd inverse_columns = r.triangularView<Eigen::Upper>().transpose().solve(unit);
  r.triangularView<Eigen::Upper>().solveInPlace(inverse_columns);
  const Eigen::LLT<Eigen::MatrixXd> n_bb(inverse_columns.middleRows(first, k));
  const auto remove_rows = [&](const Eigen::MatrixXd& m) {
    Eigen::MatrixXd out(n - k, m.cols());
    out.topRows(first) = m.topRows(first);
    out.bottomRows(n - k - first) = m.bottomRows(n - k - first);
    return out;
  };
  const Eigen::MatrixXd n_ab = remove_rows(inverse_columns);
  for (auto& [c, cached] : z_)
    cached.z = remove_rows(cached.z) - n_ab * n_bb.solve(cached.z.middleRows(first, k));

  // R: drop the node's rows and columns; the trailing block absorbs the dropped rows by
  // rank-one updates, R33'^T R33' = R33^T R33 + R23^T R23.
  const int trailing = n - first - k;
  if (trailing > 0) {
    for (int row = 0; row < k; ++row) {
      Eigen::VectorXd v = r.block(first + row, first + k, 1, trailing).transpose();
      cholesky_rank_one_update(r.block(first + k, first + k, trailing, trailing), v);
    }
  }
  remove_rows_and_columns(r_, n, first, k);
  remove_rows_and_columns(l_bb_, n, first, k);
  // Rows [first, first + trailing) of the moved columns below the diagonal must be zero.
  r_.topLeftCorner(n - k, n - k).triangularView<Eigen::StrictlyLower>().setZero();

  b_dofs_.erase(b_dofs_.begin() + first, b_dofs_.begin() + first + k);
  b_nodes_.erase(it);
  b_node_offset_.erase(b_node_offset_.begin() + static_cast<std::ptrdiff_t>(position));
  for (std::size_t i = position; i < b_node_offset_.size(); ++i) b_node_offset_[i] -= k;
  n_ = n - k;
  ++stats_.leaves;
  after_update();
}

void IncrementalCondensation::set_boundary_nodes(std::span<const int> nodes) {
  const std::vector<int> current = b_nodes_;
  for (int node : current)
    if (std::find(nodes.begin(), nodes.end(), node) == nodes.end()) remove_boundary_node(node);
  std::vector<int> joining;
  for (int node : nodes)
    if (!in_boundary(node) && std::find(joining.begin(), joining.end(), node) == joining.end()) joining.push_back(node);
  columns_.compute_columns(joining);  // one multi-right-hand-side solve for them all
  // Many at once (a step-delay set): append them to L_BB and factor once, O(|B|^3 / 3),
  // cheaper than as many bordering steps.
  if (joining.size() <= kBulkJoin) {
    for (int node : joining) add_boundary_node(node);
    return;
  }
  std::vector<int> new_dofs;
  for (int node : joining) {
    const std::vector<int> node_dofs = free_dofs_of_nodes(dofs_, std::span<const int>(&node, 1));
    if (node_dofs.empty()) continue;
    b_node_offset_.push_back(n_ + static_cast<int>(new_dofs.size()));
    b_nodes_.push_back(node);
    new_dofs.insert(new_dofs.end(), node_dofs.begin(), node_dofs.end());
  }
  const auto k = static_cast<int>(new_dofs.size());
  ensure_capacity(n_ + k);
  const Eigen::MatrixXd l_new = gather_compliance(columns_, b_dofs_, new_dofs);
  Eigen::MatrixXd lambda = gather_compliance(columns_, new_dofs, new_dofs);
  l_bb_.block(0, n_, n_, k) = l_new;
  l_bb_.block(n_, 0, k, n_) = l_new.transpose();
  l_bb_.block(n_, n_, k, k) = 0.5 * (lambda + lambda.transpose());
  b_dofs_.insert(b_dofs_.end(), new_dofs.begin(), new_dofs.end());
  n_ += k;
  stats_.joins += static_cast<long>(joining.size());
  factor_from_scratch(
      "the boundary nodes cannot be held together: L_BB is not positive definite (duplicate nodes, or a numerically "
      "singular set)");
}

void IncrementalCondensation::compute_z(std::span<const int> nodes) {
  std::vector<int> missing;
  for (int node : nodes)
    if (!z_.count(node) && std::find(missing.begin(), missing.end(), node) == missing.end()) missing.push_back(node);
  if (missing.empty()) return;
  const std::vector<int> dofs = free_dofs_of_nodes(dofs_, missing);
  Eigen::MatrixXd z = gather_compliance(columns_, b_dofs_, dofs);
  if (n_ > 0) {
    const auto r = r_.topLeftCorner(n_, n_);
    r.triangularView<Eigen::Upper>().transpose().solveInPlace(z);
    r.triangularView<Eigen::Upper>().solveInPlace(z);
  }
  Eigen::Index col = 0;
  for (int node : missing) {
    const auto width = static_cast<Eigen::Index>(free_dofs_of_nodes(dofs_, std::span<const int>(&node, 1)).size());
    z_[node] = CachedZ{z.middleCols(col, width), clock_};
    col += width;
  }
}

CondensedOperator IncrementalCondensation::condense(std::span<const int> contact_nodes) {
  ++clock_;
  for (int node : contact_nodes)
    if (in_boundary(node)) throw Error(fmt::format("node {} is both a contact and a boundary node", node));
  if (options_.naive) return naive_condensation(columns_, dofs_, contact_nodes, b_nodes_);
  compute_z(contact_nodes);

  CondensedOperator op;
  op.contact_dofs = free_dofs_of_nodes(dofs_, contact_nodes);
  op.boundary_dofs = b_dofs_;
  const auto m = static_cast<Eigen::Index>(op.contact_dofs.size());
  Eigen::MatrixXd z_c(n_, m);
  Eigen::Index col = 0;
  for (int node : contact_nodes) {
    CachedZ& cached = z_.at(node);
    cached.last_used = clock_;
    z_c.middleCols(col, cached.z.cols()) = cached.z;
    col += cached.z.cols();
  }
  const Eigen::MatrixXd l_bc = gather_compliance(columns_, b_dofs_, op.contact_dofs);
  Eigen::MatrixXd s = gather_compliance(columns_, op.contact_dofs, op.contact_dofs) - l_bc.transpose() * z_c;
  s = 0.5 * (s + s.transpose()).eval();
  const Eigen::LLT<Eigen::MatrixXd> llt(s);
  if (llt.info() != Eigen::Success)
    throw NumericalError(fmt::format(
        "the condensed compliance of {} contact dofs (with {} boundary dofs held) is not positive definite",
        m, n_));
  op.condition_estimate = cholesky_condition_estimate(llt.matrixL());
  op.m_cc = llt.solve(Eigen::MatrixXd::Identity(m, m));
  op.m_cc = 0.5 * (op.m_cc + op.m_cc.transpose()).eval();
  op.m_cb = -op.m_cc * z_c.transpose();

  // Keep the cache bounded: forget the least recently used nodes beyond the limit.
  while (z_.size() > options_.z_cache_nodes) {
    auto oldest = std::min_element(z_.begin(), z_.end(),
                                   [](const auto& a, const auto& b) { return a.second.last_used < b.second.last_used; });
    if (oldest->second.last_used == clock_) break;
    z_.erase(oldest);
  }
  return op;
}

Eigen::MatrixXd IncrementalCondensation::solve_boundary(const Eigen::MatrixXd& rhs) const {
  if (rhs.rows() != n_) throw Error(fmt::format("solve_boundary: {} rows for {} boundary dofs", rhs.rows(), n_));
  Eigen::MatrixXd x = rhs;
  if (n_ > 0) {
    const auto r = r_.topLeftCorner(n_, n_);
    r.triangularView<Eigen::Upper>().transpose().solveInPlace(x);
    r.triangularView<Eigen::Upper>().solveInPlace(x);
  }
  return x;
}

void IncrementalCondensation::after_update() {
  if (++updates_since_check_ < options_.check_interval) return;
  updates_since_check_ = 0;
  if (check_residuals() > options_.drift_tolerance) refactor();
}

double IncrementalCondensation::check_residuals() {
  ++stats_.residual_checks;
  double worst = 0;
  if (n_ > 0) {
    const auto l = l_bb_.topLeftCorner(n_, n_);
    const auto r = r_.topLeftCorner(n_, n_);
    // A deterministic probe vector: the factor must reproduce L_BB on it.
    Eigen::VectorXd x(n_);
    for (int i = 0; i < n_; ++i) x[i] = std::sin(1.0 + 0.7 * i + 0.013 * static_cast<double>(stats_.residual_checks));
    const double scale = l.norm() * x.norm();
    const Eigen::VectorXd rx = r.triangularView<Eigen::Upper>() * x;
    const Eigen::VectorXd lx = l * x;
    worst = (r.triangularView<Eigen::Upper>().transpose() * rx - lx).norm() / scale;
    // And one cached Z, in turn: L_BB Z_c must equal L_Bc.
    if (!z_.empty()) {
      auto entry = z_.begin();
      std::advance(entry, stats_.residual_checks % static_cast<long>(z_.size()));
      const Eigen::MatrixXd l_bc = column_rows_at_boundary(entry->first);
      const double z_scale = l.norm() * entry->second.z.norm() + l_bc.norm();
      worst = std::max(worst, (l * entry->second.z - l_bc).norm() / z_scale);
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
    const Eigen::LLT<Eigen::MatrixXd> llt(l_bb_.topLeftCorner(n_, n_));
    if (llt.info() != Eigen::Success) throw NumericalError(fmt::format("{} ({} boundary dofs)", failure, n_));
    r_.topLeftCorner(n_, n_) = llt.matrixU();
  }
  std::vector<int> cached;
  for (const auto& entry : z_) cached.push_back(entry.first);
  z_.clear();
  compute_z(cached);
}

}  // namespace cohaptic
