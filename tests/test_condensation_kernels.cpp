// The dense kernels of the incremental condensation against Eigen's own (a second
// implementation): triangular solves with the own narrow kernel (1-3 right-hand sides,
// every panel remainder) and with BLAS (more), products in every transposition, and the
// rank-k Cholesky update (in place, and into the place of removed rows and columns).
// Operands are blocks inside larger buffers, as in the condensation, with NaN wherever a
// kernel must not read or write.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <vector>

#include "common/condense/dense_kernels.h"
#include "common/util/error.h"
#include "common/util/not_a_number.h"

namespace cohaptic {
namespace {

// A well-conditioned lower Cholesky factor of size n, at offset (2, 3) of a buffer whose
// every other entry, the strictly upper triangle included, is NaN.
Eigen::MatrixXd factor_in_buffer(Eigen::Index n, unsigned seed) {
  std::srand(seed);
  const Eigen::MatrixXd m = Eigen::MatrixXd::Random(n, n);
  const Eigen::MatrixXd spd =
      m * m.transpose() + static_cast<double>(n) * Eigen::MatrixXd::Identity(n, n);
  Eigen::MatrixXd buffer = Eigen::MatrixXd::Constant(n + 7, n + 5, kNaN);
  buffer.block(2, 3, n, n).triangularView<Eigen::Lower>() = Eigen::MatrixXd(spd.llt().matrixL());
  return buffer;
}

TEST(CondensationKernels, TriangularSolvesEqualEigens) {
  for (Eigen::Index n : {1, 2, 3, 4, 5, 8, 37, 130})
    for (Eigen::Index columns : {1, 2, 3, 4, 9}) {
      const Eigen::MatrixXd buffer = factor_in_buffer(n, static_cast<unsigned>(n * 10 + columns));
      const auto g = buffer.block(2, 3, n, n);
      const Eigen::MatrixXd lower = g.triangularView<Eigen::Lower>();
      const Eigen::MatrixXd rhs = Eigen::MatrixXd::Random(n, columns);
      const Eigen::MatrixXd forward = lower.triangularView<Eigen::Lower>().solve(rhs);
      const Eigen::MatrixXd backward = lower.transpose().triangularView<Eigen::Upper>().solve(rhs);
      // x sits in a larger buffer too: nothing around it may change.
      Eigen::MatrixXd x_buffer = Eigen::MatrixXd::Constant(n + 4, columns + 2, kNaN);
      x_buffer.block(1, 1, n, columns) = rhs;
      solve_lower_in_place(g, x_buffer.block(1, 1, n, columns));
      EXPECT_LE((x_buffer.block(1, 1, n, columns) - forward).norm(), 1e-13 * forward.norm())
          << "forward, n " << n << ", " << columns << " right-hand sides";
      x_buffer.block(1, 1, n, columns) = rhs;
      solve_lower_transposed_in_place(g, x_buffer.block(1, 1, n, columns));
      EXPECT_LE((x_buffer.block(1, 1, n, columns) - backward).norm(), 1e-13 * backward.norm())
          << "backward, n " << n << ", " << columns << " right-hand sides";
      x_buffer.block(1, 1, n, columns).setZero();
      EXPECT_TRUE(x_buffer.array().isNaN().count() == x_buffer.size() - n * columns)
          << "wrote outside x, n " << n;
    }
}

TEST(CondensationKernels, ProductsEqualEigensInEveryTransposition) {
  const Eigen::MatrixXd a = Eigen::MatrixXd::Random(7, 5), b = Eigen::MatrixXd::Random(5, 6);
  const Eigen::MatrixXd at = a.transpose(), bt = b.transpose();
  const Eigen::MatrixXd c0 = Eigen::MatrixXd::Random(7, 6);
  const Eigen::MatrixXd expected = -2.0 * a * b + 0.5 * c0;
  struct Case {
    const Eigen::MatrixXd& a;
    Transposed ta;
    const Eigen::MatrixXd& b;
    Transposed tb;
  };
  for (const Case& product :
       {Case{a, Transposed::no, b, Transposed::no}, Case{at, Transposed::yes, b, Transposed::no},
        Case{a, Transposed::no, bt, Transposed::yes},
        Case{at, Transposed::yes, bt, Transposed::yes}}) {
    Eigen::MatrixXd c = c0;
    multiply(-2.0, product.a, product.ta, product.b, product.tb, 0.5, c);
    EXPECT_LE((c - expected).norm(), 1e-14 * expected.norm());
  }
  // beta = 0 ignores what c held, NaN included, also with an empty inner dimension.
  Eigen::MatrixXd c = Eigen::MatrixXd::Constant(7, 6, kNaN);
  multiply(1.0, a, Transposed::no, b, Transposed::no, 0.0, c);
  EXPECT_LE((c - a * b).norm(), 1e-14 * (a * b).norm());
  c.setConstant(kNaN);
  multiply(1.0, Eigen::MatrixXd(7, 0), Transposed::no, Eigen::MatrixXd(0, 6), Transposed::no, 0.0,
           c);
  EXPECT_TRUE(c.isZero());
  EXPECT_THROW(multiply(1.0, a, Transposed::yes, b, Transposed::no, 0.0, c), Error);
  Eigen::MatrixXd four_rows(4, 1);
  EXPECT_THROW(solve_lower_in_place(Eigen::MatrixXd::Identity(3, 3), four_rows), Error);
}

TEST(CondensationKernels, RankUpdateGivesTheFactorOfTheUpdatedMatrix) {
  for (Eigen::Index n : {1, 5, 40})
    for (Eigen::Index k : {1, 2, 3}) {
      Eigen::MatrixXd buffer = factor_in_buffer(n, static_cast<unsigned>(n + k));
      const Eigen::MatrixXd g = buffer.block(2, 3, n, n).triangularView<Eigen::Lower>();
      const Eigen::MatrixXd w = Eigen::MatrixXd::Random(n, k);
      const Eigen::MatrixXd expected = g * g.transpose() + w * w.transpose();
      Eigen::MatrixXd scratch = w;
      cholesky_rank_update(buffer.block(2, 3, n, n), scratch, buffer.block(2, 3, n, n));
      const Eigen::MatrixXd lower = buffer.block(2, 3, n, n).triangularView<Eigen::Lower>();
      EXPECT_LE((lower * lower.transpose() - expected).norm(), 1e-14 * expected.norm())
          << "n " << n << ", k " << k;
      EXPECT_GT(lower.diagonal().minCoeff(), 0) << "n " << n;
      // Nothing outside the lower triangle was touched: it is all still NaN.
      EXPECT_EQ(buffer.array().isNaN().count(), buffer.size() - n * (n + 1) / 2) << "n " << n;
    }
}

// As when a node leaves: the factor of the matrix without rows and columns [2, 5), its
// lower right block written straight to its new place, 3 rows and columns up.
TEST(CondensationKernels, RankUpdateIntoTheRemovedRowsPlaceGivesTheReducedFactor) {
  const Eigen::Index n = 30, first = 2, k = 3, below = n - first - k;
  Eigen::MatrixXd buffer = factor_in_buffer(n, 17);
  const Eigen::MatrixXd g = buffer.block(2, 3, n, n).triangularView<Eigen::Lower>();
  std::vector<Eigen::Index> kept;
  for (Eigen::Index i = 0; i < n; ++i)
    if (i < first || i >= first + k) kept.push_back(i);
  const Eigen::MatrixXd l = g * g.transpose();
  const Eigen::MatrixXd reduced = l(kept, kept);
  auto factor = buffer.block(2, 3, n, n);
  Eigen::MatrixXd dropped = factor.block(first + k, first, below, k);
  cholesky_rank_update(factor.block(first + k, first + k, below, below), dropped,
                       factor.block(first, first, below, below));
  // Rows below the node in the columns before it move up by k, as the condensation does.
  for (Eigen::Index col = 0; col < first; ++col)
    factor.col(col).segment(first, below) = factor.col(col).segment(first + k, below).eval();
  const Eigen::MatrixXd moved = factor.topLeftCorner(n - k, n - k).triangularView<Eigen::Lower>();
  EXPECT_LE((moved * moved.transpose() - reduced).norm(), 1e-14 * reduced.norm());
}

}  // namespace
}  // namespace cohaptic
