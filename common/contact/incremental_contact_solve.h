// The unilateral contact problem (unilateral_contact_solve.h) solved again and again for one
// normal compliance W [m/N] over many candidates while only the clearances q [m] change: at
// every haptic tick, or every simulation step, as the tools move. The active set K and the
// Cholesky factor of W_KK are kept from one solve to the next, so a solve whose set does not
// change costs two triangular solves and a check, O(|K|^2), and each node that joins or
// leaves K another O(|K|^2), instead of a factorisation, O(|K|^3).
//
// Method: block principal pivoting from the kept set, as unilateral_contact_solve.h (Judice
// and Pires; after three block moves without fewer offending nodes, Murty's single move of
// the offending candidate of largest index, which ends for every positive definite W). A
// joining node borders the factor (one triangular solve); a leaving node's row is deleted
// and the block below it updated by rank one (dense_kernels.h). Candidates outside K are
// checked through W's rows against K only; while every push is non-negative, a candidate
// with q_j >= 0 whose row of W has no negative entry cannot penetrate and is not checked at
// all (the caller says which rows those are: for contact on a body's surface, nearly all).
// A candidate with a non-finite q has no constraint now (no tool reaches it): it never
// joins, and leaves K first.
//
// Work is counted in multiply-adds; past the caller's budget a solve stops (each call makes
// one pass and one change of the set at least, so that it can overrun by about 2 |K|^2 + c|K|),
// reports that it did not resolve, and keeps its set and factor: the next solve goes on
// from there. The
// answer is the one solution of the problem; which path led to it changes its last bits
// only (the factor is updated, not recomputed), so a caller that must reproduce a result
// bit for bit repeats the same sequence of solves (as a replay does).
//
// No allocation after construction (every buffer has the capacity's size); solve() is
// noexcept. Not thread-safe: one owner at a time.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "common/contact/unilateral_contact_solve.h"

namespace cohaptic {

class IncrementalContactSolve {
 public:
  IncrementalContactSolve() = default;
  /// Room for `capacity` candidates (all of which may be in K). Allocates.
  explicit IncrementalContactSolve(int capacity);

  int capacity() const { return static_cast<int>(position_.size()); }
  /// K: candidate indices in the factor's order.
  std::span<const int> members() const {
    return {members_.data(), static_cast<std::size_t>(size_)};
  }
  /// The last solve's push [N] of members()[p].
  double member_push(int p) const { return push_[static_cast<Eigen::Index>(p)]; }
  /// All of them, in members() order.
  std::span<const double> member_pushes() const {
    return {push_.data(), static_cast<std::size_t>(size_)};
  }
  /// The push of candidate i [N] (zero outside K).
  double push(int candidate) const;
  /// W_iK lambda_K for every candidate i of the last solve's q, as its last pass found them
  /// with the set it returned, when that pass read them down the members' columns (many
  /// more candidates than members); empty otherwise.
  std::span<const double> w_push() const {
    return {w_push_.data(), static_cast<std::size_t>(w_push_count_)};
  }
  bool in_set(int candidate) const { return position_[static_cast<std::size_t>(candidate)] >= 0; }
  /// L, lower triangular, W_KK = L L^T (members() order).
  Eigen::Ref<const Eigen::MatrixXd> factor() const { return factor_.topLeftCorner(size_, size_); }

  /// K becomes `set` (candidate indices, each once), with W_KK factored afresh: O(|K|^3),
  /// for a start off the haptic thread. Returns false (and K empty) if W_KK is not positive
  /// definite or `set` is not within the capacity.
  bool start_from(const Eigen::Ref<const Eigen::MatrixXd>& w, std::span<const int> set);
  /// K empty.
  void clear() noexcept;
  /// Candidate i leaves K if it is in it (one rank-one update), e.g. before its index is
  /// given to another node.
  void remove(int candidate) noexcept;

  /// Solves for `q` (one per candidate, at most capacity(); +inf: no constraint) with `w`
  /// (at least q.size() square; the same W as the kept factor's), from the kept set.
  /// `nonnegative_row[j]` (q.size() entries) is non-zero when row j of W has no negative
  /// entry. Stops past `max_work` multiply-adds. solved is false if the budget ran out or
  /// W_KK lost positive definiteness (then K is emptied).
  UnilateralSolveResult solve(const Eigen::Ref<const Eigen::MatrixXd>& w,
                              const Eigen::Ref<const Eigen::VectorXd>& q,
                              std::span<const std::uint8_t> nonnegative_row,
                              double max_work) noexcept;

 private:
  /// Appends candidate j to K (borders the factor); false if the pivot is not positive.
  bool join(const Eigen::Ref<const Eigen::MatrixXd>& w, int j) noexcept;
  /// Removes the member at factor position p (rank-one update of the rows below).
  void leave(int p) noexcept;

  int size_ = 0;
  PivotRule rule_;            // since the last solved call
  Eigen::MatrixXd factor_;    // lower triangle of the top-left size_ x size_: L, W_KK = L L^T
  Eigen::VectorXd push_;      // per factor position: the pushes of the last solve
  Eigen::VectorXd w_push_;    // per candidate: W_iK lambda_K of the last pass read down the columns
  int w_push_count_ = 0;      // its valid length: 0 once K has changed since
  Eigen::VectorXd scratch_;   // a column for borders and updates
  std::vector<int> members_;  // per factor position: the candidate
  std::vector<int> position_;   // per candidate: its factor position, or -1
  std::vector<int> offending_;  // candidates that break a condition in this pass
};

}  // namespace cohaptic
