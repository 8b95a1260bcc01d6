// Rank-k update of a lower Cholesky factor: from G with G G^T = L to G' with
// G' G'^T = L + W W^T, in O(k n^2) instead of the O(n^3) of factoring L + W W^T again.
//
// It is how a node leaves the boundary set: with the node's rows and columns gone, the
// trailing block of the factor absorbs the rows that were removed above it. Each column
// is a sequence of plane rotations (the classical update, stable: no subtraction, the
// diagonal only grows). Invariant kept: G lower triangular with a positive diagonal.
#pragma once

#include <Eigen/Core>

namespace cohaptic {

/// `g`: n x n, lower triangle read and written, strictly upper part not touched; `w`:
/// n x k, overwritten (garbage afterwards).
void cholesky_rank_update(Eigen::Ref<Eigen::MatrixXd> g, Eigen::Ref<Eigen::MatrixXd> w);

}  // namespace cohaptic
