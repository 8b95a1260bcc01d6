// The unilateral contact problem (unilateral_contact_solve.h) over many candidate nodes of
// which few touch: the sphere contact model's candidates are every touchable node near the
// spheres, including those outside a sphere at rest that the deformation may carry in.
//
// Method: solve over a working set K (the warm start and every candidate that penetrates
// with no push, q_i < 0), then compute the clearance w_j = q_j + sum_{i in K} A_ji lambda_i
// of every candidate outside K; every one with w_j < 0 joins K and K is solved again. K only
// grows, so this ends, and at the end the conditions hold over all candidates: for a
// positive definite A the one solution, whatever the warm start (the inner solve factors
// A_SS in ascending candidate order, so the answer depends on the final set alone). Only
// rows of A against K are ever formed: a pass costs about |K|^3/3 + 9 (m - |K|) |K|
// multiply-adds, and the caller's limit applies to |K|, not to the candidates.
//
// `entry(i, j)` gives A_ij [m/N] for a candidate j in K (it is never asked for a column
// outside K; the K x K block is read from its lower triangle, entry(i, j) with i >= j).
// `on_set(members)` is called before each pass with K's candidates, ascending, so that the
// caller can prepare their columns. Allocation-free given the scratch; noexcept when the
// callables are.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <span>

#include "common/contact/unilateral_contact_solve.h"

namespace cohaptic {

/// The working space of one solve over m candidates. Matrix and Vector are resized to the
/// working set (a compile-time maximum size keeps them off the heap); the spans hold at
/// least m entries.
template <class Matrix, class Vector>
struct WorkingSetScratch {
  Matrix a, factor;
  Vector q, lambda;
  std::span<int> members;                 ///< K's candidates, ascending
  std::span<std::uint8_t> member_active;  ///< the inner solve's set, per member
  std::span<int> order;                   ///< the inner solve's ordering
  std::span<std::uint8_t> in_set;         ///< per candidate: in K
};

struct WorkingSetSolveResult {
  UnilateralSolveResult inner;  ///< summed over the passes; solved is false on any failure
  int passes = 0;
  int largest_set = 0;         ///< |K| at the end
  bool set_too_large = false;  ///< K outgrew max_set (then solved is false)
};

/// `q` has m entries; `active` (m) is the warm start on entry (non-zero: in contact) and the
/// final set on exit; `lambda` (m) the pushes [N], zero outside the set. `max_set` bounds
/// |K| and `max_work` the multiply-adds of all passes.
template <class Entry, class OnSet, class Matrix, class Vector>
WorkingSetSolveResult solve_unilateral_over_candidates(const Eigen::Ref<const Eigen::VectorXd>& q,
                                                       Entry&& entry, OnSet&& on_set, int max_set,
                                                       std::span<std::uint8_t> active,
                                                       Eigen::Ref<Eigen::VectorXd> lambda,
                                                       WorkingSetScratch<Matrix, Vector>& scratch,
                                                       double max_work) {
  WorkingSetSolveResult result;
  const auto m = static_cast<int>(q.size());
  // K starts as the warm start and every candidate that penetrates with no push, all of it
  // active in the first pass; a candidate that joins later starts active too.
  int size = 0;
  for (int i = 0; i < m; ++i) {
    const bool in = active[static_cast<std::size_t>(i)] != 0 || q[i] < 0;
    scratch.in_set[static_cast<std::size_t>(i)] = in;
    active[static_cast<std::size_t>(i)] = in;
    size += in;
  }
  lambda.setZero();
  for (;;) {
    result.largest_set = size;
    if (size == 0) {  // nothing penetrates and nothing was pushed: no push at all
      result.inner.solved = true;
      return result;
    }
    if (size > max_set) {
      result.set_too_large = true;
      result.inner.solved = false;
      return result;
    }
    ++result.passes;
    for (int i = 0, k = 0; i < m; ++i)
      if (scratch.in_set[static_cast<std::size_t>(i)])
        scratch.members[static_cast<std::size_t>(k++)] = i;
    const std::span<const int> members = scratch.members.first(static_cast<std::size_t>(size));
    on_set(members);
    scratch.a.resize(size, size);
    scratch.factor.resize(size, size);
    scratch.q.resize(size);
    scratch.lambda.resize(size);
    for (int r = 0; r < size; ++r) {
      const int i = members[static_cast<std::size_t>(r)];
      scratch.q[r] = q[i];
      scratch.member_active[static_cast<std::size_t>(r)] = active[static_cast<std::size_t>(i)];
      for (int c = 0; c <= r; ++c)
        scratch.a(r, c) = scratch.a(c, r) = entry(i, members[static_cast<std::size_t>(c)]);
    }
    const double work_left = max_work - result.inner.work;
    const UnilateralSolveResult pass = solve_unilateral_contact(
        scratch.a, scratch.q, scratch.member_active.first(static_cast<std::size_t>(size)),
        scratch.lambda, scratch.factor, scratch.order, work_left);
    result.inner.trials += pass.trials;
    result.inner.work += pass.work;
    if (!pass.solved) return result;

    // Every candidate outside K that the pushes carry into its sphere joins it.
    int joining = 0;
    for (int j = 0; j < m; ++j) {
      if (scratch.in_set[static_cast<std::size_t>(j)]) continue;
      double clearance = q[j];
      for (int r = 0; r < size; ++r)
        if (scratch.lambda[r] != 0)
          clearance += entry(j, members[static_cast<std::size_t>(r)]) * scratch.lambda[r];
      result.inner.work += 9.0 * size;
      if (clearance < 0) {
        scratch.in_set[static_cast<std::size_t>(j)] = 1;
        active[static_cast<std::size_t>(j)] = 1;
        ++joining;
      }
    }
    for (int r = 0; r < size; ++r) {
      const int i = members[static_cast<std::size_t>(r)];
      active[static_cast<std::size_t>(i)] = scratch.member_active[static_cast<std::size_t>(r)];
      lambda[i] = scratch.lambda[r];
    }
    if (joining == 0) {
      result.inner.solved = true;
      return result;
    }
    if (result.inner.work > max_work) return result;
    size += joining;
  }
}

}  // namespace cohaptic
