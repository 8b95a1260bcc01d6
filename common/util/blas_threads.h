// Keeping BLAS (OpenBLAS, behind CHOLMOD) on the calling thread, and letting it use more
// for a while.
//
// The server shares the machine with haptic clients, whose 1 kHz loops must not compete
// with BLAS worker threads spinning on every core; and a single thread makes every solve's
// rounding the same from run to run, which bit-exact replay relies on. A long computation
// at load (the Schur complement's factorisation) may use more threads, always the same
// number of them: OpenBLAS's rounding depends on it.
#pragma once

#include <string>

namespace cohaptic {

/// BLAS threads for a factorisation or a dense inverse at load: always this many, whatever
/// the machine, since OpenBLAS's rounding depends on its thread count and a replay must
/// factor as the session did.
constexpr int kFactorBlasThreads = 2;

/// The kernels BLAS chose for this CPU ("Haswell", "SkylakeX", ...: OpenBLAS's core name,
/// which OPENBLAS_CORETYPE overrides), or "unknown" with another BLAS.
std::string blas_kernels();

/// The dense flop rate [flop/s] BLAS reaches here on kFactorBlasThreads threads: a matrix
/// product's, measured once per process (a few milliseconds) and remembered. An estimate
/// for a progress line's time left, not a promise.
double dense_flop_rate();

/// Asks OpenBLAS for one thread. A no-op with a BLAS that has no such control.
void use_single_blas_thread();

/// OpenBLAS on `threads` threads while this object lives, then as many as before. The count
/// is the process's: use it only where no other thread calls BLAS meanwhile (loading a scene).
class ScopedBlasThreads {
 public:
  explicit ScopedBlasThreads(int threads);
  ~ScopedBlasThreads();
  ScopedBlasThreads(const ScopedBlasThreads&) = delete;
  ScopedBlasThreads& operator=(const ScopedBlasThreads&) = delete;

 private:
  int before_ = 1;
};

}  // namespace cohaptic
