#include "common/contact/incremental_contact_solve.h"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/condense/dense_kernels.h"

namespace cohaptic {
namespace {

// The round-off allowance of the checks, as in unilateral_contact_solve.cpp.
constexpr double kRelativeTolerance = 1e-12;

}  // namespace

IncrementalContactSolve::IncrementalContactSolve(int capacity)
    : factor_(Eigen::MatrixXd::Zero(std::max(capacity, 1), std::max(capacity, 1))),
      push_(Eigen::VectorXd::Zero(std::max(capacity, 1))),
      w_push_(Eigen::VectorXd::Zero(std::max(capacity, 1))),
      scratch_(Eigen::VectorXd::Zero(std::max(capacity, 1))),
      members_(static_cast<std::size_t>(std::max(capacity, 0)), -1),
      position_(static_cast<std::size_t>(std::max(capacity, 0)), -1) {
  offending_.reserve(position_.size());
}

double IncrementalContactSolve::push(int candidate) const {
  const int p = position_[static_cast<std::size_t>(candidate)];
  return p < 0 ? 0.0 : push_[p];
}

void IncrementalContactSolve::clear() noexcept {
  for (int p = 0; p < size_; ++p)
    position_[static_cast<std::size_t>(members_[static_cast<std::size_t>(p)])] = -1;
  size_ = 0;
  w_push_count_ = 0;
}

void IncrementalContactSolve::remove(int candidate) noexcept {
  if (candidate < 0 || candidate >= capacity()) return;
  if (const int p = position_[static_cast<std::size_t>(candidate)]; p >= 0) leave(p);
}

bool IncrementalContactSolve::start_from(const Eigen::Ref<const Eigen::MatrixXd>& w,
                                         std::span<const int> set) {
  clear();
  const auto k = static_cast<Eigen::Index>(set.size());
  for (int j : set)
    if (j < 0 || j >= capacity() || j >= w.rows()) return false;
  if (k == 0) return true;
  Eigen::MatrixXd w_kk(k, k);
  for (Eigen::Index a = 0; a < k; ++a)
    for (Eigen::Index b = 0; b < k; ++b)
      w_kk(a, b) = w(set[static_cast<std::size_t>(a)], set[static_cast<std::size_t>(b)]);
  const Eigen::LLT<Eigen::MatrixXd> llt(w_kk);
  if (llt.info() != Eigen::Success) return false;
  factor_.topLeftCorner(k, k) = llt.matrixL();
  for (Eigen::Index p = 0; p < k; ++p) {
    const int j = set[static_cast<std::size_t>(p)];
    if (position_[static_cast<std::size_t>(j)] >= 0) {  // listed twice
      clear();
      return false;
    }
    members_[static_cast<std::size_t>(p)] = j;
    position_[static_cast<std::size_t>(j)] = static_cast<int>(p);
    push_[p] = 0;
  }
  size_ = static_cast<int>(k);
  return true;
}

bool IncrementalContactSolve::join(const Eigen::Ref<const Eigen::MatrixXd>& w, int j) noexcept {
  w_push_count_ = 0;
  const Eigen::Index k = size_;
  // The new row of L: l = L^-1 W_Kj, and its diagonal sqrt(W_jj - l^T l).
  for (Eigen::Index p = 0; p < k; ++p) scratch_[p] = w(members_[static_cast<std::size_t>(p)], j);
  if (k > 0) solve_lower_in_place(factor_.topLeftCorner(k, k), scratch_.head(k));
  const double pivot = w(j, j) - scratch_.head(k).squaredNorm();
  if (!(pivot > 0)) return false;
  factor_.row(k).head(k) = scratch_.head(k).transpose();
  factor_(k, k) = std::sqrt(pivot);
  members_[static_cast<std::size_t>(k)] = j;
  position_[static_cast<std::size_t>(j)] = static_cast<int>(k);
  push_[k] = 0;
  ++size_;
  return true;
}

void IncrementalContactSolve::leave(int p) noexcept {
  w_push_count_ = 0;
  const Eigen::Index k = size_, below = k - p - 1;
  if (below > 0) {
    // The block below the row takes it in by a rank-one update, one row and column up and
    // to the left; the rows below it in the columns before it move up one row.
    scratch_.head(below) = factor_.col(p).segment(p + 1, below);
    cholesky_rank_update(factor_.block(p + 1, p + 1, below, below), scratch_.head(below),
                         factor_.block(p, p, below, below));
    for (Eigen::Index c = 0; c < p; ++c)
      std::copy(factor_.col(c).data() + p + 1, factor_.col(c).data() + k,
                factor_.col(c).data() + p);
  }
  position_[static_cast<std::size_t>(members_[static_cast<std::size_t>(p)])] = -1;
  for (Eigen::Index q = p; q + 1 < k; ++q) {
    members_[static_cast<std::size_t>(q)] = members_[static_cast<std::size_t>(q + 1)];
    position_[static_cast<std::size_t>(members_[static_cast<std::size_t>(q)])] =
        static_cast<int>(q);
    push_[q] = push_[q + 1];
  }
  --size_;
}

UnilateralSolveResult IncrementalContactSolve::solve(const Eigen::Ref<const Eigen::MatrixXd>& w,
                                                     const Eigen::Ref<const Eigen::VectorXd>& q,
                                                     std::span<const std::uint8_t> nonnegative_row,
                                                     double max_work) noexcept {
  UnilateralSolveResult result;
  const auto m = static_cast<int>(std::min<Eigen::Index>(q.size(), capacity()));
  // A member no tool reaches any more leaves first.
  for (int p = size_ - 1; p >= 0; --p)
    if (!std::isfinite(q[members_[static_cast<std::size_t>(p)]])) {
      result.work += 2.0 * (size_ - p) * (size_ - p);
      leave(p);
    }
  // Scales of the clearances [m] and of the pushes [N], for the round-off allowances.
  double clearance_scale = 0, push_scale = 0;
  for (int i = 0; i < m; ++i)
    if (std::isfinite(q[i])) {
      clearance_scale = std::max(clearance_scale, std::abs(q[i]));
      if (w(i, i) > 0) push_scale = std::max(push_scale, std::abs(q[i]) / w(i, i));
    }
  result.work += 2.0 * m;
  const double clearance_tolerance = kRelativeTolerance * clearance_scale;
  const double push_tolerance = kRelativeTolerance * push_scale;

  // Every call makes one pass and one move at least, so that calls with a small budget
  // still progress; the pivot rule's counts carry over to the next call, which goes on
  // where this one stopped rather than repeat it.
  do {
    ++result.trials;
    const Eigen::Index k = size_;
    // The pushes of K: W_KK lambda = -q_K.
    for (Eigen::Index p = 0; p < k; ++p) push_[p] = -q[members_[static_cast<std::size_t>(p)]];
    if (k > 0) {
      solve_lower_in_place(factor_.topLeftCorner(k, k), push_.head(k));
      solve_lower_transposed_in_place(factor_.topLeftCorner(k, k), push_.head(k));
    }
    result.work += static_cast<double>(k) * static_cast<double>(k);

    // W_jK lambda_K for the candidates: where they are many times the members (the server's
    // whole surface against the tools' contact), once for every row, down the members'
    // columns, which W holds contiguously; otherwise a gathered dot per candidate checked.
    const bool down_columns = m > 4 * k;
    w_push_count_ = 0;
    if (down_columns) {
      result.work +=
          static_cast<double>(k) * static_cast<double>(m);  // the budget sees the whole pass
      w_push_.head(m).setZero();
      for (Eigen::Index p = 0; p < k; ++p)
        w_push_.head(m).noalias() +=
            push_[p] * w.col(members_[static_cast<std::size_t>(p)]).head(m);
      w_push_count_ = m;
    }

    // Offending: members with a negative push (they leave), then candidates outside K that
    // penetrate (they join).
    offending_.clear();
    for (Eigen::Index p = 0; p < k; ++p)
      if (push_[p] < -push_tolerance) offending_.push_back(members_[static_cast<std::size_t>(p)]);
    auto leaving = static_cast<std::ptrdiff_t>(offending_.size());
    const bool any_negative = leaving > 0;
    for (int j = 0; j < m; ++j) {
      if (position_[static_cast<std::size_t>(j)] >= 0 || !std::isfinite(q[j])) continue;
      // With no negative push, a row of W without negative entries only moves j away.
      if (!any_negative && q[j] >= 0 && nonnegative_row[static_cast<std::size_t>(j)]) continue;
      // W_jK lambda_K, read down column j (W is symmetric), unless read down K's columns.
      if (!down_columns) result.work += static_cast<double>(k);
      const double reach = down_columns
                               ? w_push_[j]
                               : gathered_dot(w.col(j).data(), members_.data(), push_.data(), k);
      if (q[j] + reach < -clearance_tolerance) offending_.push_back(j);
    }
    if (offending_.empty()) {
      rule_.reset();
      result.solved = true;
      return result;
    }
    if (!rule_.block_move(
            static_cast<int>(offending_.size()))) {  // Murty: only the candidate of largest index
      const auto largest = std::max_element(offending_.begin(), offending_.end());
      const bool leaves = largest - offending_.begin() < leaving;
      offending_.assign(1, *largest);
      leaving = leaves ? 1 : 0;
    }
    const auto joining = offending_.begin() + leaving;
    // Leaving members first, from the last factor position up (each update is cheaper
    // there), then the joining candidates in ascending order.
    std::sort(offending_.begin(), joining, [&](int a, int b) {
      return position_[static_cast<std::size_t>(a)] > position_[static_cast<std::size_t>(b)];
    });
    // Past the budget the moves stop too (after one at least): the next call goes on.
    bool moved = false;
    for (auto it = offending_.begin(); it != joining && !(moved && result.work > max_work);
         ++it, moved = true) {
      const int p = position_[static_cast<std::size_t>(*it)];
      result.work += 2.0 * static_cast<double>(size_ - p) * static_cast<double>(size_ - p);
      leave(p);
    }
    std::sort(joining, offending_.end());
    for (auto it = joining; it != offending_.end() && !(moved && result.work > max_work);
         ++it, moved = true) {
      result.work += 0.5 * static_cast<double>(size_) * static_cast<double>(size_) + size_;
      if (!join(w, *it)) {  // W_KK lost positive definiteness: no answer, and no set to keep
        clear();
        return result;
      }
    }
  } while (result.work <= max_work);
  return result;
}

}  // namespace cohaptic
