// Keeping BLAS (OpenBLAS, behind CHOLMOD) on the calling thread.
//
// The server shares the machine with haptic clients, whose 1 kHz loops must not compete
// with BLAS worker threads spinning on every core; and a single thread makes every solve's
// rounding the same from run to run, which bit-exact replay relies on.
#pragma once

namespace cohaptic {

/// Asks OpenBLAS for one thread. A no-op with a BLAS that has no such control.
void use_single_blas_thread();

}  // namespace cohaptic
