// The unilateral (frictionless) contact problem in compliance form, one normal unknown per
// candidate node: find the push lambda_i >= 0 [N] that a rigid tool exerts on each
// candidate node along the node's contact normal, such that
//   w = A lambda + q >= 0   and   lambda_i w_i = 0 for every i,
// where A [m/N] is the candidates' normal compliance (A_ij = n_i^T L_ij n_j, symmetric
// positive definite) and q [m] each node's normal clearance from the tool when no
// candidate is loaded (negative: the node would lie inside the tool). w is the clearance
// under the pushes: a node is pushed exactly when it touches the tool, and a node the
// tool would have to pull is released. For a positive definite A this linear
// complementarity problem has exactly one solution.
//
// Method: block principal pivoting (Judice and Pires, 1994). From a warm-start set S of
// active nodes it solves A_SS lambda_S = -q_S, then moves every node that breaks a
// condition (lambda < 0 in S, w < 0 outside) to the other side; once three block moves in
// a row have not lowered the count of such nodes, it moves only the offending node of
// largest index (Murty's rule), which ends for every positive definite A. Every trial
// factors A_SS afresh in ascending node order, so the answer depends on the final set
// alone, never on the warm start or the path taken. The caller bounds the work: past the
// budget it reports failure rather than a guess. noexcept and allocation-free: the caller
// provides the workspace.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <span>

namespace cohaptic {

/// Judice and Pires' choice of move in block principal pivoting: every offending node at
/// once while that lowers the count of offending nodes below the fewest seen, and for
/// three more passes without that; then only one (Murty's rule: the offending node of
/// largest index) until the count falls below the fewest seen again. Ends for every
/// positive definite matrix.
class PivotRule {
 public:
  /// After a pass that left `offending` (> 0) nodes offending: true to move them all,
  /// false to move only the one of largest index.
  bool block_move(int offending) noexcept;
  /// A new problem (or a solved one): no count seen yet.
  void reset() noexcept;

 private:
  static constexpr int kBlockMovesWithoutProgress = 3;  // Judice and Pires' p
  int fewest_offending_ = std::numeric_limits<int>::max();
  int block_moves_left_ = kBlockMovesWithoutProgress;
};

struct UnilateralSolveResult {
  bool solved = false;  ///< false: A_SS was not positive definite, or the work budget ran out
  int trials = 0;       ///< active sets factored
  double work = 0;      ///< multiply-adds spent
};

/// `a` is m x m and `q` has m entries. `active` (m entries) is the warm start on entry
/// (non-zero: in contact) and the solution's set on exit; `lambda` (m) receives the pushes
/// (zero outside the set). `factor` must be at least m x m and `order` at least m long.
/// `max_work` bounds the multiply-adds (each trial costs about k^3/3 + (m - k) k for k
/// active nodes).
UnilateralSolveResult solve_unilateral_contact(const Eigen::Ref<const Eigen::MatrixXd>& a,
                                               const Eigen::Ref<const Eigen::VectorXd>& q,
                                               std::span<std::uint8_t> active,
                                               Eigen::Ref<Eigen::VectorXd> lambda,
                                               Eigen::Ref<Eigen::MatrixXd> factor,
                                               std::span<int> order, double max_work) noexcept;

}  // namespace cohaptic
