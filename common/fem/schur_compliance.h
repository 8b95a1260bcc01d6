// The compliance among a set of dofs R, L_RR = (K^-1)[R, R], dense, by the Schur-complement
// route: one sparse Cholesky factorisation of K with R ordered last, then the inverse of
// the factor's trailing block.
//
// With R last, K = [K_II K_IR; K_RI K_RR] factors as [L_II 0; L_RI L_RR], where
// L_RR L_RR^T = S = K_RR - K_RI K_II^-1 K_IR, the Schur complement, and (K^-1)[R, R] = S^-1.
// This costs one factorisation (the interior in its own fill-reducing order, the trailing
// m x m block dense: m^3/3 flops more) and the inverse from the factor (2m^3/3 flops),
// instead of m solves each as dear as the factor's nonzeros (ComplianceColumns). Memory:
// the factor and the m x m result (8 m^2 bytes).
//
// Units: those of K^-1 (m/N for K in N/m). Invariants: the result is symmetric, exactly;
// the same K and R give the same bits on a machine: the factorisation and the inverse
// always run BLAS on kFactorBlasThreads threads (OpenBLAS's rounding depends on their number).
#pragma once

#include <Eigen/Core>
#include <span>

#include "common/fem/assemble_stiffness.h"
#include "common/fem/compliance.h"
#include "common/util/progress_log.h"

namespace cohaptic {

/// (K^-1)[rows, rows] in `rows`' order for the symmetric positive definite `k` (its lower
/// triangle read). `rows`: distinct indices into k. `progress`, if given, is told the flops
/// of the whole (the factorisation's, as CHOLMOD's analysis counts them, and the inverse's),
/// the machine's dense flop rate, and each part as it begins and ends. Throws NumericalError
/// if K is not positive definite or CHOLMOD fails.
Eigen::MatrixXd schur_compliance(const SparseMatrix& k, std::span<const int> rows,
                                 ProgressLog* progress = nullptr);

/// Every row node's column block of `columns` that is missing, all at once by the Schur route
/// on K_ff (`k_ff`, in `dofs`' free indices): L[row_nodes, row_nodes] in one go. Returns the
/// columns added.
std::size_t compute_row_columns_by_schur(ComplianceColumns& columns, const SparseMatrix& k_ff,
                                         const DofMap& dofs, ProgressLog* progress = nullptr);

}  // namespace cohaptic
