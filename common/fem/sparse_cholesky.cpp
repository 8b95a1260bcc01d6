#include "common/fem/sparse_cholesky.h"

#include <fmt/format.h>

#include "common/fem/cholmod_view.h"
#include "common/util/blas_threads.h"
#include "common/util/error.h"

namespace cohaptic {

// The factor with the common it was analysed and factored with (read-only afterwards).
struct SparseCholesky::Impl : OwnedCholmodFactor {};

// cholmod_solve2's reusable outputs and the common whose workspace the solve uses.
struct CholeskyWorkspace::Impl {
  cholmod_common common{};
  cholmod_dense* solution = nullptr;
  cholmod_dense* work_y = nullptr;
  cholmod_dense* work_e = nullptr;

  Impl() { start_cholmod_common(common); }
  ~Impl() {
    cholmod_free_dense(&solution, &common);
    cholmod_free_dense(&work_y, &common);
    cholmod_free_dense(&work_e, &common);
    cholmod_finish(&common);
  }
};

CholeskyWorkspace::CholeskyWorkspace() : impl_(std::make_unique<Impl>()) {}
CholeskyWorkspace::~CholeskyWorkspace() = default;
CholeskyWorkspace::CholeskyWorkspace(CholeskyWorkspace&&) noexcept = default;
CholeskyWorkspace& CholeskyWorkspace::operator=(CholeskyWorkspace&&) noexcept = default;

SparseCholesky::SparseCholesky(const SparseMatrix& matrix, const RowNamer& name_row,
                               ProgressLog* progress)
    : impl_(std::make_unique<Impl>()), size_(static_cast<int>(matrix.rows())) {
  if (matrix.rows() != matrix.cols())
    throw NumericalError(
        fmt::format("cannot factor a {}x{} matrix: not square", matrix.rows(), matrix.cols()));
  if (!matrix.isCompressed()) throw NumericalError("cannot factor an uncompressed sparse matrix");
  cholmod_sparse view = cholmod_view_of(matrix);
  cholmod_common& c = impl_->common;
  impl_->factor = cholmod_analyze(&view, &c);
  if (impl_->factor == nullptr || c.status < CHOLMOD_OK)
    throw NumericalError(
        fmt::format("CHOLMOD analysis of a {0}x{0} matrix failed (status {1})", size_, c.status));
  if (progress) {
    progress->set_total(c.fl);
    progress->begin_part(c.fl, dense_flop_rate());
  }
  int ok = 0;
  {
    const ScopedBlasThreads blas(kFactorBlasThreads);
    ok = cholmod_factorize(&view, impl_->factor, &c);
  }
  if (progress) progress->add(c.fl);
  if (c.status == CHOLMOD_NOT_POSDEF) {
    const auto failed_column = static_cast<std::size_t>(impl_->factor->minor);
    const int row = failed_column < static_cast<std::size_t>(size_)
                        ? static_cast<int*>(impl_->factor->Perm)[failed_column]
                        : -1;
    throw NumericalError(fmt::format(
        "the stiffness matrix is not positive definite ({}): is every part of the object fixed "
        "against rigid motion, and are the material and elements valid?",
        row >= 0 && name_row ? "first failure at " + name_row(row) : fmt::format("row {}", row)));
  }
  if (!ok || c.status < CHOLMOD_OK)
    throw NumericalError(fmt::format(
        "CHOLMOD factorisation of a {0}x{0} matrix failed (status {1})", size_, c.status));
  reciprocal_condition_ = cholmod_rcond(impl_->factor, &c);
  factor_nonzeros_ = c.lnz;
}

SparseCholesky::~SparseCholesky() = default;

Eigen::MatrixXd SparseCholesky::solve(const Eigen::MatrixXd& rhs) const {
  CholeskyWorkspace workspace;
  return solve(rhs, workspace);
}

Eigen::MatrixXd SparseCholesky::solve(const Eigen::MatrixXd& rhs,
                                      CholeskyWorkspace& workspace) const {
  if (rhs.rows() != size_)
    throw NumericalError(
        fmt::format("solve: right-hand side has {} rows, the factor {}", rhs.rows(), size_));
  Eigen::MatrixXd x(rhs.rows(), rhs.cols());
  if (rhs.cols() == 0) return x;
  cholmod_dense b{};
  b.nrow = static_cast<std::size_t>(rhs.rows());
  b.ncol = static_cast<std::size_t>(rhs.cols());
  b.nzmax = b.nrow * b.ncol;
  b.d = b.nrow;
  b.x = const_cast<double*>(rhs.data());
  b.xtype = CHOLMOD_REAL;
  b.dtype = CHOLMOD_DOUBLE;
  CholeskyWorkspace::Impl& w = *workspace.impl_;
  if (!cholmod_solve2(CHOLMOD_A, impl_->factor, &b, nullptr, &w.solution, nullptr, &w.work_y,
                      &w.work_e, &w.common))
    throw NumericalError(fmt::format("CHOLMOD solve failed (status {})", w.common.status));
  const auto* values = static_cast<const double*>(w.solution->x);
  const auto leading = static_cast<Eigen::Index>(w.solution->d);
  for (Eigen::Index j = 0; j < x.cols(); ++j)
    x.col(j) = Eigen::Map<const Eigen::VectorXd>(values + j * leading, x.rows());
  return x;
}

bool SparseCholesky::is_supernodal() const { return impl_->factor->is_super != 0; }

}  // namespace cohaptic
