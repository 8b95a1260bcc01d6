// DeferredCholesky: the CHOLMOD factorisation of a sparse symmetric positive definite
// matrix (a body's K_ff), computed once, when first asked for.
//
// A body whose compliance columns all come from the disk cache never needs its K_ff factor
// (the columns are its solves), so loading it costs no factorisation. A program that will
// solve asks for the factor at load (factor()), where a matrix that is not positive
// definite should be reported. The factorisation uses CHOLMOD's BLAS threads
// (ScopedBlasThreads), so the first call must come while no other thread calls BLAS.
//
// Copies share one factor. factor() is thread-safe; if the factorisation throws, the
// caller gets the error and the next call tries again.
#pragma once

#include <memory>

#include "common/fem/sparse_cholesky.h"

namespace cohaptic {

class DeferredCholesky {
 public:
  DeferredCholesky() = default;  ///< empty: factor() throws
  /// Keeps `matrix` (only its lower triangle is read) until it is factored.
  DeferredCholesky(SparseMatrix matrix, SparseCholesky::RowNamer name_row);
  /// A factor the caller made and owns, which must outlive every copy of this handle.
  static DeferredCholesky borrowing(const SparseCholesky& factor);

  /// The factor, computed on the first call (SparseCholesky's constructor: it throws
  /// NumericalError naming the row where positive definiteness failed), which reports to
  /// `progress` if given.
  const SparseCholesky& factor(ProgressLog* progress = nullptr) const;
  const SparseCholesky& operator*() const { return factor(); }
  const SparseCholesky* operator->() const { return &factor(); }

  bool factored() const;
  /// Wall time the factorisation took [ms]; 0 before it.
  double factor_ms() const;

 private:
  struct State;
  std::shared_ptr<State> state_;
};

}  // namespace cohaptic
