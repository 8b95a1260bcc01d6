#include "common/util/blas_threads.h"

#include <algorithm>
#include <vector>

#include "common/util/stopwatch.h"

extern "C" void openblas_set_num_threads(int) __attribute__((weak));
extern "C" int openblas_get_num_threads() __attribute__((weak));
extern "C" char* openblas_get_corename() __attribute__((weak));
extern "C" void dgemm_(const char* transa, const char* transb, const int* m, const int* n,
                       const int* k, const double* alpha, const double* a, const int* lda,
                       const double* b, const int* ldb, const double* beta, double* c,
                       const int* ldc);

namespace cohaptic {

void use_single_blas_thread() {
  if (openblas_set_num_threads) openblas_set_num_threads(1);
}

ScopedBlasThreads::ScopedBlasThreads(int threads) {
  if (openblas_get_num_threads) before_ = openblas_get_num_threads();
  if (openblas_set_num_threads) openblas_set_num_threads(threads);
}

ScopedBlasThreads::~ScopedBlasThreads() {
  if (openblas_set_num_threads) openblas_set_num_threads(before_);
}

std::string blas_kernels() { return openblas_get_corename ? openblas_get_corename() : "unknown"; }

namespace {

// The faster of two products of n x n matrices: the first also pays for waking BLAS's
// threads and touching the memory.
double measure_dense_flop_rate() {
  constexpr int n = 768;
  const std::vector<double> a(static_cast<std::size_t>(n) * n, 0.5),
      b(static_cast<std::size_t>(n) * n, 0.25);
  std::vector<double> c(static_cast<std::size_t>(n) * n);
  const double one = 1, zero = 0;
  const ScopedBlasThreads blas(kFactorBlasThreads);
  double best_s = 0;
  for (int round = 0; round < 2; ++round) {
    Stopwatch watch;
    dgemm_("N", "N", &n, &n, &n, &one, a.data(), &n, b.data(), &n, &zero, c.data(), &n);
    const double seconds = watch.elapsed_ms() / 1000;
    best_s = round == 0 ? seconds : std::min(best_s, seconds);
  }
  return 2.0 * n * n * n / std::max(best_s, 1e-6);
}

}  // namespace

double dense_flop_rate() {
  static const double rate = measure_dense_flop_rate();
  return rate;
}

}  // namespace cohaptic
