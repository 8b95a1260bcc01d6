#include "common/util/blas_threads.h"

extern "C" void openblas_set_num_threads(int) __attribute__((weak));
extern "C" int openblas_get_num_threads() __attribute__((weak));

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

}  // namespace cohaptic
