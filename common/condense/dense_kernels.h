// The dense kernels of the incremental condensation: triangular solves, products and the
// rank-k update of a Cholesky factor, on column-major blocks (unit inner stride, e.g.
// corners of capacity buffers).
//
// A boundary change costs a few triangular solves with a factor of up to 3000 x 3000 and
// k <= 3 right-hand sides, and a leave a rank-k update of the factor below the node; a
// condensation, two products of |B| x |C| blocks. Eigen's
// kernels are compiled for the portable x86-64 baseline (SSE2); OpenBLAS (already behind
// CHOLMOD) picks its kernels for the CPU at run time but packs the factor before solving,
// which doubles the memory traffic for so few right-hand sides. So: up to 3 right-hand
// sides, an own kernel that reads the factor once, built for the baseline and for AVX2 +
// FMA and chosen at load time (so is the rank-k update); more, and every product, BLAS.
// Measured per solve with 3
// right-hand sides, n = 900 / 3000: Eigen 0.37 / 8.9 ms, OpenBLAS 0.21 / 3.8 ms, own
// kernel 0.12 / 2.2 ms. A triangle's other half is never read. Results are bit-identical
// from run to run on one machine and BLAS thread count.
#pragma once

#include <Eigen/Core>

namespace cohaptic {

using MatrixRef = Eigen::Ref<Eigen::MatrixXd>;
using ConstMatrixRef = Eigen::Ref<const Eigen::MatrixXd>;

/// x <- G^-1 x for G lower triangular (n x n, non-zero diagonal), x n x k.
void solve_lower_in_place(const ConstMatrixRef& g, MatrixRef x);
/// x <- G^-T x for G lower triangular.
void solve_lower_transposed_in_place(const ConstMatrixRef& g, MatrixRef x);

enum class Transposed { no, yes };
/// c <- alpha op(a) op(b) + beta c, op(m) = m or m^T as `transposed_*` says.
void multiply(double alpha, const ConstMatrixRef& a, Transposed transposed_a,
              const ConstMatrixRef& b, Transposed transposed_b, double beta, MatrixRef c);

/// Rank-k update (k <= 3) of a lower Cholesky factor: from G (n x n, G G^T = L, positive
/// diagonal) to G' with G' G'^T = L + W W^T, in O(k n^2) instead of the O(n^3) of factoring
/// again. It is how a node leaves the boundary set: the block of the factor below the node
/// absorbs the rows removed above it. Plane rotations, column by column: stable (no
/// subtraction; the diagonal only grows). G' goes to `updated`, which may be `g` itself or
/// lie up and to the left of it in the same buffer (where the removed rows and columns
/// were): column j of G is read before anything is written over a later column. Only lower
/// triangles are read or written; `w` (n x k) is overwritten.
void cholesky_rank_update(const ConstMatrixRef& g, MatrixRef w, MatrixRef updated);

/// sum over p < n of column[index[p]] * values[p], summed in four interleaved partial sums
/// (so the result does not depend on the CPU the kernel was built for): a row of a
/// symmetric matrix, read down its column, against a vector on some of its entries.
double gathered_dot(const double* column, const int* index, const double* values,
                    Eigen::Index n) noexcept;

}  // namespace cohaptic
