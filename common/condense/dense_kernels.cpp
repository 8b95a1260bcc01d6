#include "common/condense/dense_kernels.h"

#include <cblas.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "common/util/error.h"

// The narrow solves are compiled twice on x86-64 with GCC, for the baseline and for
// x86-64-v3 (AVX2 + FMA), and the loader picks one for the CPU; `flatten` inlines the
// templates into each version, so both are really built for their target.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define COHAPTIC_CPU_CLONES __attribute__((target_clones("default", "arch=x86-64-v3"), flatten))
#else
#define COHAPTIC_CPU_CLONES __attribute__((flatten))
#endif

namespace cohaptic {
namespace {

// Up to this many right-hand sides the own kernels beat BLAS (which packs the factor).
constexpr Eigen::Index kNarrowColumns = 3;
// Columns of G swept together: each row of x below a panel is loaded and stored once per
// panel, and kPanel x R accumulators fit the registers.
constexpr int kPanel = 4;
// Independent partial sums per dot product, so that the compiler may vectorise the sums
// without reordering a floating-point reduction itself.
constexpr int kLanes = 4;

// x <- G^-1 x for R right-hand sides (strides ld, ldx): column panels of G; after a
// panel's diagonal block, every row below is updated by the whole panel at once.
template <int R>
void forward_substitution(Eigen::Index n, const double* __restrict g, Eigen::Index ld,
                          double* __restrict x, Eigen::Index ldx) {
  for (Eigen::Index first = 0; first < n; first += kPanel) {
    const Eigen::Index width = std::min<Eigen::Index>(kPanel, n - first);
    for (Eigen::Index j = first; j < first + width; ++j) {
      const double* column = g + j * ld;
      for (int r = 0; r < R; ++r) {
        double* xr = x + r * ldx;
        xr[j] /= column[j];
        for (Eigen::Index i = j + 1; i < first + width; ++i) xr[i] -= column[i] * xr[j];
      }
    }
    if (width < kPanel) break;  // a partial panel is the last: no rows below it
    double solved[R][kPanel];
    for (int r = 0; r < R; ++r)
      for (int p = 0; p < kPanel; ++p) solved[r][p] = x[r * ldx + first + p];
    const double* panel = g + first * ld;
    for (Eigen::Index i = first + kPanel; i < n; ++i)
      for (int r = 0; r < R; ++r) {
        double sum = 0;
        for (int p = 0; p < kPanel; ++p) sum += panel[p * ld + i] * solved[r][p];
        x[r * ldx + i] -= sum;
      }
  }
}

// x <- G^-T x for R right-hand sides: panels from the bottom up; a panel's rows take the
// dot products of its columns with the rows already solved below it, then its diagonal
// block. The bottom panel takes the remainder, so it is the only partial one and has no
// rows below.
template <int R>
void backward_substitution(Eigen::Index n, const double* __restrict g, Eigen::Index ld,
                           double* __restrict x, Eigen::Index ldx) {
  Eigen::Index end = n;
  Eigen::Index width = n % kPanel == 0 ? kPanel : n % kPanel;
  while (end > 0) {
    const Eigen::Index first = end - width;
    double dot[R][kPanel] = {};
    if (end < n) {
      const double* panel = g + first * ld;
      double partial[R][kPanel][kLanes] = {};
      Eigen::Index i = end;
      for (; i + kLanes <= n; i += kLanes)
        for (int r = 0; r < R; ++r)
          for (int p = 0; p < kPanel; ++p)
            for (int l = 0; l < kLanes; ++l)
              partial[r][p][l] += panel[p * ld + i + l] * x[r * ldx + i + l];
      for (int r = 0; r < R; ++r)
        for (int p = 0; p < kPanel; ++p) {
          for (int l = 0; l < kLanes; ++l) dot[r][p] += partial[r][p][l];
          for (Eigen::Index tail = i; tail < n; ++tail)
            dot[r][p] += panel[p * ld + tail] * x[r * ldx + tail];
        }
    }
    for (Eigen::Index j = end - 1; j >= first; --j) {
      const double* column = g + j * ld;
      for (int r = 0; r < R; ++r) {
        double value = x[r * ldx + j] - dot[r][j - first];
        for (Eigen::Index i = j + 1; i < end; ++i) value -= column[i] * x[r * ldx + i];
        x[r * ldx + j] = value / column[j];
      }
    }
    end = first;
    width = kPanel;
  }
}

// G' G'^T = G G^T + W W^T for K update columns: per column of G, the K rotations' cosines
// and sines from its diagonal, then one sweep down the column applying all K to each row
// of G and of W. Reads column j of g, writes column j of out (which may alias g, see
// cholesky_rank_update).
template <int K>
void rank_update(Eigen::Index n, const double* g, Eigen::Index ld, double* out, Eigen::Index ld_out,
                 double* __restrict w, Eigen::Index ldw) {
  for (Eigen::Index j = 0; j < n; ++j) {
    const double* column = g + j * ld;
    double* target = out + j * ld_out;
    double sine[K], cosine[K], inverse_cosine[K];
    double diagonal = column[j];
    for (int r = 0; r < K; ++r) {
      const double w_j = w[r * ldw + j];
      const double radius = std::hypot(diagonal, w_j);
      sine[r] = w_j / diagonal;
      cosine[r] = radius / diagonal;
      inverse_cosine[r] = diagonal / radius;
      diagonal = radius;
    }
    target[j] = diagonal;
    for (Eigen::Index i = j + 1; i < n; ++i) {
      double value = column[i];
      for (int r = 0; r < K; ++r) {
        double& update = w[r * ldw + i];
        value = (value + sine[r] * update) * inverse_cosine[r];
        update = update * cosine[r] - sine[r] * value;
      }
      target[i] = value;
    }
  }
}

COHAPTIC_CPU_CLONES void narrow_rank_update(Eigen::Index n, const double* g, Eigen::Index ld,
                                            double* out, Eigen::Index ld_out, double* w,
                                            Eigen::Index ldw, Eigen::Index k) {
  if (k == 1) rank_update<1>(n, g, ld, out, ld_out, w, ldw);
  if (k == 2) rank_update<2>(n, g, ld, out, ld_out, w, ldw);
  if (k == 3) rank_update<3>(n, g, ld, out, ld_out, w, ldw);
}

COHAPTIC_CPU_CLONES void narrow_forward_substitution(Eigen::Index n, const double* g,
                                                     Eigen::Index ld, double* x, Eigen::Index ldx,
                                                     Eigen::Index columns) {
  if (columns == 1) forward_substitution<1>(n, g, ld, x, ldx);
  if (columns == 2) forward_substitution<2>(n, g, ld, x, ldx);
  if (columns == 3) forward_substitution<3>(n, g, ld, x, ldx);
}

COHAPTIC_CPU_CLONES void narrow_backward_substitution(Eigen::Index n, const double* g,
                                                      Eigen::Index ld, double* x, Eigen::Index ldx,
                                                      Eigen::Index columns) {
  if (columns == 1) backward_substitution<1>(n, g, ld, x, ldx);
  if (columns == 2) backward_substitution<2>(n, g, ld, x, ldx);
  if (columns == 3) backward_substitution<3>(n, g, ld, x, ldx);
}

COHAPTIC_CPU_CLONES double gathered_dot_kernel(const double* __restrict column,
                                               const int* __restrict index,
                                               const double* __restrict values, Eigen::Index n) {
  double sum[kLanes] = {};
  Eigen::Index p = 0;
  for (; p + kLanes <= n; p += kLanes)
    for (int l = 0; l < kLanes; ++l) sum[l] += column[index[p + l]] * values[p + l];
  for (; p < n; ++p) sum[0] += column[index[p]] * values[p];
  return (sum[0] + sum[1]) + (sum[2] + sum[3]);
}

int blas_size(Eigen::Index size) { return static_cast<int>(size); }
// BLAS wants a leading dimension of at least 1, even for an empty block.
int leading_dimension(const ConstMatrixRef& m) {
  return static_cast<int>(std::max<Eigen::Index>({1, m.rows(), m.outerStride()}));
}
CBLAS_TRANSPOSE blas_transpose(Transposed transposed) {
  return transposed == Transposed::yes ? CblasTrans : CblasNoTrans;
}

// x <- G^-1 x or G^-T x.
void solve_lower(const ConstMatrixRef& g, MatrixRef x, Transposed transposed) {
  if (g.rows() != g.cols() || g.rows() != x.rows())
    throw Error(fmt::format(
        "{}: a {} x {} triangle against {} rows",
        transposed == Transposed::yes ? "solve_lower_transposed_in_place" : "solve_lower_in_place",
        g.rows(), g.cols(), x.rows()));
  if (x.rows() == 0 || x.cols() == 0) return;
  if (x.cols() <= kNarrowColumns) {
    const auto narrow =
        transposed == Transposed::yes ? narrow_backward_substitution : narrow_forward_substitution;
    narrow(x.rows(), g.data(), g.outerStride(), x.data(), x.outerStride(), x.cols());
  } else {
    cblas_dtrsm(CblasColMajor, CblasLeft, CblasLower, blas_transpose(transposed), CblasNonUnit,
                blas_size(x.rows()), blas_size(x.cols()), 1.0, g.data(), leading_dimension(g),
                x.data(), leading_dimension(x));
  }
}

}  // namespace

void solve_lower_in_place(const ConstMatrixRef& g, MatrixRef x) {
  solve_lower(g, x, Transposed::no);
}

void solve_lower_transposed_in_place(const ConstMatrixRef& g, MatrixRef x) {
  solve_lower(g, x, Transposed::yes);
}

void multiply(double alpha, const ConstMatrixRef& a, Transposed transposed_a,
              const ConstMatrixRef& b, Transposed transposed_b, double beta, MatrixRef c) {
  const Eigen::Index rows = transposed_a == Transposed::yes ? a.cols() : a.rows();
  const Eigen::Index inner = transposed_a == Transposed::yes ? a.rows() : a.cols();
  const Eigen::Index b_inner = transposed_b == Transposed::yes ? b.cols() : b.rows();
  const Eigen::Index cols = transposed_b == Transposed::yes ? b.rows() : b.cols();
  if (rows != c.rows() || cols != c.cols() || inner != b_inner)
    throw Error(fmt::format("multiply: op(a) {} x {} times op(b) {} x {} into {} x {}", rows, inner,
                            b_inner, cols, c.rows(), c.cols()));
  if (rows == 0 || cols == 0) return;
  if (inner == 0) {  // BLAS semantics: beta = 0 ignores what c held, NaN included
    if (beta == 0)
      c.setZero();
    else
      c *= beta;
    return;
  }
  cblas_dgemm(CblasColMajor, blas_transpose(transposed_a), blas_transpose(transposed_b),
              blas_size(rows), blas_size(cols), blas_size(inner), alpha, a.data(),
              leading_dimension(a), b.data(), leading_dimension(b), beta, c.data(),
              leading_dimension(c));
}

double gathered_dot(const double* column, const int* index, const double* values,
                    Eigen::Index n) noexcept {
  return gathered_dot_kernel(column, index, values, n);
}

void cholesky_rank_update(const ConstMatrixRef& g, MatrixRef w, MatrixRef updated) {
  const Eigen::Index n = g.rows();
  if (g.cols() != n || updated.rows() != n || updated.cols() != n || w.rows() != n || w.cols() > 3)
    throw Error(fmt::format(
        "cholesky_rank_update: a {} x {} factor, {} x {} updates (at most 3 columns), into {} x {}",
        n, g.cols(), w.rows(), w.cols(), updated.rows(), updated.cols()));
  if (n == 0) return;
  narrow_rank_update(n, g.data(), g.outerStride(), updated.data(), updated.outerStride(), w.data(),
                     w.outerStride(), w.cols());
}

}  // namespace cohaptic
