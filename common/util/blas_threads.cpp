#include "common/util/blas_threads.h"

extern "C" void openblas_set_num_threads(int) __attribute__((weak));

namespace cohaptic {

void use_single_blas_thread() {
  if (openblas_set_num_threads) openblas_set_num_threads(1);
}

}  // namespace cohaptic
