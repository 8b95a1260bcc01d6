// SparseCholesky: a supernodal CHOLMOD factorisation of a sparse symmetric positive
// definite matrix (K_ff), and solves against it.
//
// The factor is immutable once built, so any number of threads may solve against it at
// once; what a solve mutates (CHOLMOD's common and dense scratch) is a CholeskyWorkspace
// owned by the caller, one per thread (MuJoCo's rule: scratch lives in the data, not in
// the model). Units are those of the matrix; solve(K, f) gives u for K in N/m and f in N.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <string>

#include "common/fem/assemble_stiffness.h"
#include "common/util/progress_log.h"

namespace cohaptic {

/// CHOLMOD's scratch for solves: reused from one solve to the next so that repeated solves
/// do not reallocate. Belongs to one thread at a time; movable, not copyable.
class CholeskyWorkspace {
 public:
  CholeskyWorkspace();
  ~CholeskyWorkspace();
  CholeskyWorkspace(CholeskyWorkspace&&) noexcept;
  CholeskyWorkspace& operator=(CholeskyWorkspace&&) noexcept;

 private:
  friend class SparseCholesky;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

class SparseCholesky {
 public:
  /// Names row i for error messages, e.g. "node 812 axis y".
  using RowNamer = std::function<std::string(int row)>;

  /// Analyses and factors `matrix` (only its lower triangle is read). `progress`, if given,
  /// is told the factorisation's flops (as CHOLMOD's analysis counts them) as its total, the
  /// machine's dense flop rate, and the part's begin and end. Throws NumericalError naming
  /// the row where positive definiteness failed.
  explicit SparseCholesky(const SparseMatrix& matrix, const RowNamer& name_row = {},
                          ProgressLog* progress = nullptr);
  ~SparseCholesky();
  SparseCholesky(const SparseCholesky&) = delete;
  SparseCholesky& operator=(const SparseCholesky&) = delete;

  int size() const { return size_; }

  /// X with matrix * X = rhs (any number of columns), using the caller's scratch.
  Eigen::MatrixXd solve(const Eigen::MatrixXd& rhs, CholeskyWorkspace& workspace) const;
  /// The same with a workspace of its own (allocated per call: for one-off solves).
  Eigen::MatrixXd solve(const Eigen::MatrixXd& rhs) const;

  /// CHOLMOD's cheap reciprocal condition estimate, (min diag L / max diag L)^2.
  double reciprocal_condition_estimate() const { return reciprocal_condition_; }
  /// Nonzeros stored in the factor (a memory and cost figure for logs and benchmarks).
  double factor_nonzeros() const { return factor_nonzeros_; }
  bool is_supernodal() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int size_ = 0;
  double reciprocal_condition_ = 0;
  double factor_nonzeros_ = 0;
};

}  // namespace cohaptic
