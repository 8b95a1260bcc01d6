#include "common/fem/spd_inverse_from_factor.h"

#include <algorithm>
#include <atomic>
#include <functional>
#include <thread>
#include <vector>

// BLAS (OpenBLAS), Fortran interface.
extern "C" {
void dtrsm_(const char* side, const char* uplo, const char* transa, const char* diag, const int* m, const int* n,
            const double* alpha, const double* a, const int* lda, double* b, const int* ldb);
void dgemm_(const char* transa, const char* transb, const int* m, const int* n, const int* k, const double* alpha,
            const double* a, const int* lda, const double* b, const int* ldb, const double* beta, double* c, const int* ldc);
}

namespace cohaptic {

namespace {

constexpr int kBlock = 192;  // columns per block: large enough for BLAS's own blocking, small enough to balance

// Runs task(0), ..., task(count - 1), each once, on `threads` threads, in order of taking.
void run_tasks(int count, int threads, const std::function<void(int)>& task) {
  std::atomic<int> next{0};
  const auto work = [&] {
    for (int t = next.fetch_add(1); t < count; t = next.fetch_add(1)) task(t);
  };
  std::vector<std::thread> helpers;
  for (int k = 1; k < std::min(threads, count); ++k) helpers.emplace_back(work);
  work();
  for (std::thread& helper : helpers) helper.join();
}

int block_count(int m) { return (m + kBlock - 1) / kBlock; }
int block_start(int block) { return block * kBlock; }
int block_width(int m, int block) { return std::min(kBlock, m - block * kBlock); }

// Flops of the triangular solve of block column J, and of block (I, J) of Z^T Z.
double solve_flops(int m, int block) {
  const double rows = m - block_start(block);
  return rows * rows * block_width(m, block);
}
double product_flops(int m, int i, int j) {
  return 2.0 * block_width(m, i) * block_width(m, j) * (m - block_start(i));
}

}  // namespace

double spd_inverse_flops(int m) {
  double flops = 0;
  for (int i = 0; i < block_count(m); ++i) {
    flops += solve_flops(m, i);
    for (int j = 0; j <= i; ++j) flops += product_flops(m, i, j);
  }
  return flops;
}

void invert_spd_from_factor(Eigen::MatrixXd& factor, int threads, ProgressLog* progress) {
  const int m = static_cast<int>(factor.rows());
  if (m == 0) return;
  const int blocks = block_count(m);
  const auto start = block_start;
  const auto width = [&](int block) { return block_width(m, block); };
  const double one = 1, zero = 0;

  // Z = L^-1, lower triangular: block column J solves L[j0:, j0:] Z[j0:, J] = I[j0:, J].
  // The widest solves (the first columns) go first.
  Eigen::MatrixXd inverse_factor = Eigen::MatrixXd::Zero(m, m);
  run_tasks(blocks, threads, [&](int block) {
    const int j0 = start(block), b = width(block), rows = m - j0;
    for (int j = 0; j < b; ++j) inverse_factor(j0 + j, j0 + j) = 1;
    dtrsm_("L", "L", "N", "N", &rows, &b, &one, factor.data() + j0 + static_cast<Eigen::Index>(j0) * m, &m,
           inverse_factor.data() + j0 + static_cast<Eigen::Index>(j0) * m, &m);
    if (progress) progress->add(solve_flops(m, block));
  });

  // S^-1 = Z^T Z: block (I, J), I at or below J, sums Z's rows from i0 on (Z is zero above).
  std::vector<std::pair<int, int>> pairs;
  for (int i = 0; i < blocks; ++i)
    for (int j = 0; j <= i; ++j) pairs.emplace_back(i, j);
  run_tasks(static_cast<int>(pairs.size()), threads, [&](int task) {
    const auto [i, j] = pairs[static_cast<std::size_t>(task)];
    const int i0 = start(i), j0 = start(j), bi = width(i), bj = width(j), depth = m - i0;
    dgemm_("T", "N", &bi, &bj, &depth, &one, inverse_factor.data() + i0 + static_cast<Eigen::Index>(i0) * m, &m,
           inverse_factor.data() + i0 + static_cast<Eigen::Index>(j0) * m, &m, &zero,
           factor.data() + i0 + static_cast<Eigen::Index>(j0) * m, &m);
    if (progress) progress->add(product_flops(m, i, j));
  });
  factor.triangularView<Eigen::StrictlyUpper>() = factor.transpose().triangularView<Eigen::StrictlyUpper>();
}

}  // namespace cohaptic
