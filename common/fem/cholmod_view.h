// CHOLMOD glue shared by the factorisations in common/fem: a common set up the way cohaptic
// uses CHOLMOD (supernodal, silent: errors become exceptions), a factor that frees itself,
// and a read-only CHOLMOD view of an Eigen compressed-column matrix's lower triangle (no copy).
#pragma once

#include <cholmod.h>

#include "common/fem/assemble_stiffness.h"

namespace cohaptic {

inline void start_cholmod_common(cholmod_common& common) {
  cholmod_start(&common);
  common.supernodal = CHOLMOD_SUPERNODAL;
  common.print = 0;  // errors are reported through exceptions, not stdout
  common.error_handler = nullptr;
}

/// A CHOLMOD common and the factor analysed and factored with it, freed together.
struct OwnedCholmodFactor {
  cholmod_common common{};
  cholmod_factor* factor = nullptr;
  OwnedCholmodFactor() { start_cholmod_common(common); }
  ~OwnedCholmodFactor() {
    cholmod_free_factor(&factor, &common);
    cholmod_finish(&common);
  }
  OwnedCholmodFactor(const OwnedCholmodFactor&) = delete;
  OwnedCholmodFactor& operator=(const OwnedCholmodFactor&) = delete;
};

/// `matrix` as a symmetric CHOLMOD matrix whose lower triangle is read; it must outlive the view.
inline cholmod_sparse cholmod_view_of(const SparseMatrix& matrix) {
  cholmod_sparse view{};
  view.nrow = static_cast<std::size_t>(matrix.rows());
  view.ncol = static_cast<std::size_t>(matrix.cols());
  view.nzmax = static_cast<std::size_t>(matrix.nonZeros());
  view.p = const_cast<int*>(matrix.outerIndexPtr());
  view.i = const_cast<int*>(matrix.innerIndexPtr());
  view.x = const_cast<double*>(matrix.valuePtr());
  view.stype = -1;  // symmetric, lower triangle used
  view.itype = CHOLMOD_INT;
  view.xtype = CHOLMOD_REAL;
  view.dtype = CHOLMOD_DOUBLE;
  view.sorted = 1;
  view.packed = 1;
  return view;
}

}  // namespace cohaptic
