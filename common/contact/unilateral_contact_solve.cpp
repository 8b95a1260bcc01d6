#include "common/contact/unilateral_contact_solve.h"

#include <algorithm>
#include <cmath>

namespace cohaptic {
namespace {

// Round-off allowance of the complementarity checks, relative to the problem's scales.
constexpr double kRelativeTolerance = 1e-12;

// Lower Cholesky factor of A_SS (S = order[0..k)) in `factor`; false if not positive definite.
bool factor_active_block(const Eigen::Ref<const Eigen::MatrixXd>& a, std::span<const int> order,
                         Eigen::Ref<Eigen::MatrixXd> factor) noexcept {
  const auto k = static_cast<Eigen::Index>(order.size());
  for (Eigen::Index j = 0; j < k; ++j) {
    double diagonal = a(order[j], order[j]);
    for (Eigen::Index p = 0; p < j; ++p) diagonal -= factor(j, p) * factor(j, p);
    if (!(diagonal > 0)) return false;
    factor(j, j) = std::sqrt(diagonal);
    for (Eigen::Index i = j + 1; i < k; ++i) {
      double value = a(order[i], order[j]);
      for (Eigen::Index p = 0; p < j; ++p) value -= factor(i, p) * factor(j, p);
      factor(i, j) = value / factor(j, j);
    }
  }
  return true;
}

// lambda_S = -A_SS^-1 q_S through the factor, in place in `lambda`; zero elsewhere.
void solve_active_block(const Eigen::Ref<const Eigen::VectorXd>& q, std::span<const int> order,
                        const Eigen::Ref<Eigen::MatrixXd>& factor,
                        Eigen::Ref<Eigen::VectorXd> lambda) noexcept {
  lambda.setZero();
  const auto k = static_cast<Eigen::Index>(order.size());
  for (Eigen::Index i = 0; i < k; ++i) {
    double value = -q[order[i]];
    for (Eigen::Index p = 0; p < i; ++p) value -= factor(i, p) * lambda[order[p]];
    lambda[order[i]] = value / factor(i, i);
  }
  for (Eigen::Index i = k - 1; i >= 0; --i) {
    double value = lambda[order[i]];
    for (Eigen::Index p = i + 1; p < k; ++p) value -= factor(p, i) * lambda[order[p]];
    lambda[order[i]] = value / factor(i, i);
  }
}

}  // namespace

bool PivotRule::block_move(int offending) noexcept {
  if (offending < fewest_offending_) {
    fewest_offending_ = offending;
    block_moves_left_ = kBlockMovesWithoutProgress;
    return true;
  }
  if (block_moves_left_ > 0) {
    --block_moves_left_;
    return true;
  }
  return false;
}

void PivotRule::reset() noexcept {
  fewest_offending_ = std::numeric_limits<int>::max();
  block_moves_left_ = kBlockMovesWithoutProgress;
}

UnilateralSolveResult solve_unilateral_contact(const Eigen::Ref<const Eigen::MatrixXd>& a,
                                               const Eigen::Ref<const Eigen::VectorXd>& q,
                                               std::span<std::uint8_t> active,
                                               Eigen::Ref<Eigen::VectorXd> lambda,
                                               Eigen::Ref<Eigen::MatrixXd> factor,
                                               std::span<int> order, double max_work) noexcept {
  UnilateralSolveResult result;
  const auto m = static_cast<int>(q.size());
  // Scales of the clearances [m] and of the pushes [N], for the round-off allowances.
  double clearance_scale = 0, push_scale = 0;
  for (int i = 0; i < m; ++i) {
    clearance_scale = std::max(clearance_scale, std::abs(q[i]));
    if (a(i, i) > 0) push_scale = std::max(push_scale, std::abs(q[i]) / a(i, i));
  }
  const double clearance_tolerance = kRelativeTolerance * clearance_scale;
  const double push_tolerance = kRelativeTolerance * push_scale;

  PivotRule rule;
  while (result.work <= max_work) {
    int k = 0;
    for (int i = 0; i < m; ++i)
      if (active[i]) order[static_cast<std::size_t>(k++)] = i;
    const std::span<const int> set = order.first(static_cast<std::size_t>(k));
    ++result.trials;
    result.work += static_cast<double>(k) * k * k / 3 + static_cast<double>(m - k) * k +
                   static_cast<double>(k) * k;
    if (!factor_active_block(a, set, factor)) return result;
    solve_active_block(q, set, factor, lambda);

    // Offending nodes are marked with bit 1 of `active` (bit 0 says in contact).
    int offending = 0, last_offending = -1;
    for (int i = 0; i < m; ++i) {
      bool offends = false;
      if (active[i]) {
        offends = lambda[i] < -push_tolerance;
      } else {
        double clearance = q[i];
        for (int p : set) clearance += a(i, p) * lambda[p];
        offends = clearance < -clearance_tolerance;
      }
      active[i] = static_cast<std::uint8_t>((active[i] ? 1 : 0) | (offends ? 2 : 0));
      if (offends) {
        ++offending;
        last_offending = i;
      }
    }
    result.solved = offending == 0;
    const bool block_move = result.solved || rule.block_move(offending);
    for (int i = 0; i < m; ++i) {
      const bool moves = (active[i] & 2) && (block_move || i == last_offending);
      active[i] = static_cast<std::uint8_t>((active[i] & 1) ^ (moves ? 1 : 0));
    }
    if (result.solved) return result;
  }
  return result;
}

}  // namespace cohaptic
