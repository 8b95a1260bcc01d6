// The inverse of a dense symmetric positive definite matrix S from its lower Cholesky
// factor L (S = L L^T): S^-1 = L^-T L^-1, in square blocks of kBlock columns spread over
// several threads. Every block's arithmetic is fixed (one BLAS call on one thread, the same
// operands), so the bits do not depend on the number of threads or on which thread did
// which block. Memory: a second m x m matrix while it runs.
#pragma once

#include <Eigen/Core>

#include "common/util/progress_log.h"

namespace cohaptic {

/// Replaces `factor` (m x m; its lower triangle read, L) by S^-1 (full, exactly symmetric),
/// using `threads` threads (at least 1). BLAS must run one thread per call (use_single_blas_thread).
/// Each finished block adds its flops to `progress`, if given.
void invert_spd_from_factor(Eigen::MatrixXd& factor, int threads, ProgressLog* progress = nullptr);

/// The flops invert_spd_from_factor spends on an m x m factor (its blocks', as it counts them).
double spd_inverse_flops(int m);

}  // namespace cohaptic
