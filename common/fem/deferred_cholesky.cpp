#include "common/fem/deferred_cholesky.h"

#include <atomic>
#include <mutex>

#include <spdlog/spdlog.h>

#include "common/util/error.h"
#include "common/util/stopwatch.h"

namespace cohaptic {

struct DeferredCholesky::State {
  SparseMatrix matrix;  // released once factored
  SparseCholesky::RowNamer name_row;
  std::mutex mutex;
  std::unique_ptr<const SparseCholesky> factor;  // null if borrowed
  std::atomic<const SparseCholesky*> ready{
      nullptr};  // the factor once made (or borrowed): the lock-free path
  double factor_ms = 0;
};

DeferredCholesky::DeferredCholesky(SparseMatrix matrix, SparseCholesky::RowNamer name_row)
    : state_(std::make_shared<State>()) {
  state_->matrix = std::move(matrix);
  state_->name_row = std::move(name_row);
}

DeferredCholesky DeferredCholesky::borrowing(const SparseCholesky& factor) {
  DeferredCholesky handle;
  handle.state_ = std::make_shared<State>();
  handle.state_->ready.store(&factor, std::memory_order_release);
  return handle;
}

const SparseCholesky& DeferredCholesky::factor(ProgressLog* progress) const {
  if (!state_) throw Error("no matrix to factor");
  if (const SparseCholesky* ready = state_->ready.load(std::memory_order_acquire)) return *ready;
  const std::lock_guard lock(state_->mutex);
  if (!state_->ready.load(std::memory_order_relaxed)) {
    const Stopwatch watch;
    state_->factor =
        std::make_unique<const SparseCholesky>(state_->matrix, state_->name_row, progress);
    state_->factor_ms = watch.elapsed_ms();
    spdlog::info(
        "factored the {0}x{0} stiffness matrix ({1:.3g} nonzeros in the factor) in {2:.0f} ms",
        state_->factor->size(), state_->factor->factor_nonzeros(), state_->factor_ms);
    state_->matrix = SparseMatrix();
    state_->ready.store(state_->factor.get(), std::memory_order_release);
  }
  return *state_->ready.load(std::memory_order_relaxed);
}

bool DeferredCholesky::factored() const {
  return state_ && state_->ready.load(std::memory_order_acquire) != nullptr;
}

double DeferredCholesky::factor_ms() const { return factored() ? state_->factor_ms : 0; }

}  // namespace cohaptic
