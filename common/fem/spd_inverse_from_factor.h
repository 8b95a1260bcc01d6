// The inverse of a dense symmetric positive definite matrix S from its lower Cholesky
// factor L (S = L L^T): S^-1 = L^-T L^-1, in place, by LAPACK's triangular inverse (dtrtri)
// and product (dlauum), as OpenBLAS implements them, on kFactorBlasThreads BLAS threads:
// always that many, so the bits are the same from run to run on a machine (OpenBLAS's
// rounding depends on its thread count). No second m x m matrix is needed.
#pragma once

#include <Eigen/Core>

#include "common/util/progress_log.h"

namespace cohaptic {

/// Replaces `factor` (m x m; its lower triangle read, L) by S^-1 (full, exactly symmetric).
/// Each of its two parts adds its flops to `progress`, if given (spd_inverse_flops in all).
/// Throws NumericalError if L has a zero on its diagonal.
void invert_spd_from_factor(Eigen::MatrixXd& factor, ProgressLog* progress = nullptr);

/// The flops invert_spd_from_factor spends on an m x m factor: m^3/3 for each part.
double spd_inverse_flops(int m);

}  // namespace cohaptic
