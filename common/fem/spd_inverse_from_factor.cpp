#include "common/fem/spd_inverse_from_factor.h"

#include <fmt/format.h>

#include <algorithm>

#include "common/util/blas_threads.h"
#include "common/util/error.h"

// LAPACK (OpenBLAS's own, parallel dtrtri and dlauum), Fortran interface.
extern "C" {
void dtrtri_(const char* uplo, const char* diag, const int* n, double* a, const int* lda,
             int* info);
void dlauum_(const char* uplo, const int* n, double* a, const int* lda, int* info);
}

namespace cohaptic {

namespace {

double triangular_part_flops(int m) { return static_cast<double>(m) * m * m / 3; }

// The strict upper triangle of `a` from its lower one, tile by tile: a tile's writes, along
// rows of a column-major matrix, stay within the cache lines it has just loaded.
void mirror_lower_to_upper(Eigen::MatrixXd& a) {
  constexpr Eigen::Index kTile = 32;
  const Eigen::Index m = a.rows();
  for (Eigen::Index j0 = 0; j0 < m; j0 += kTile)
    for (Eigen::Index i0 = j0; i0 < m; i0 += kTile)
      for (Eigen::Index j = j0; j < std::min(j0 + kTile, m); ++j)
        for (Eigen::Index i = std::max(i0, j + 1); i < std::min(i0 + kTile, m); ++i)
          a(j, i) = a(i, j);
}

}  // namespace

double spd_inverse_flops(int m) { return 2 * triangular_part_flops(m); }

void invert_spd_from_factor(Eigen::MatrixXd& factor, ProgressLog* progress) {
  const int m = static_cast<int>(factor.rows());
  if (m == 0) return;
  int info = 0;
  const ScopedBlasThreads blas(kFactorBlasThreads);
  // Z = L^-1, lower triangular, in place.
  if (progress) progress->begin_part(triangular_part_flops(m), dense_flop_rate());
  dtrtri_("L", "N", &m, factor.data(), &m, &info);
  if (info != 0)
    throw NumericalError(fmt::format(
        "the {0}x{0} Cholesky factor cannot be inverted: LAPACK dtrtri returned {1}", m, info));
  if (progress) progress->add(triangular_part_flops(m));
  // S^-1 = Z^T Z: its lower triangle, in place.
  if (progress) progress->begin_part(triangular_part_flops(m), dense_flop_rate());
  dlauum_("L", &m, factor.data(), &m, &info);
  if (info != 0)
    throw NumericalError(fmt::format("LAPACK dlauum returned {} on a {}x{} matrix", info, m, m));
  if (progress) progress->add(triangular_part_flops(m));
  mirror_lower_to_upper(factor);
}

}  // namespace cohaptic
