#include "common/util/progress_log.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace cohaptic {
namespace {

constexpr std::chrono::seconds kLineEvery{1};  // and the first line after it: a shorter task logs nothing
constexpr int kBarWidth = 20;

}  // namespace

ProgressLog::ProgressLog(std::string what) : what_(std::move(what)), logger_([this] { log_every_second(); }) {}

ProgressLog::~ProgressLog() {
  {
    const std::lock_guard lock(mutex_);
    stop_ = true;
  }
  stopping_.notify_all();
  logger_.join();
}

void ProgressLog::set_phase(std::string phase) {
  const std::lock_guard lock(mutex_);
  phase_ = std::move(phase);
}

void ProgressLog::set_total(double total) {
  const std::lock_guard lock(mutex_);
  total_ = total;
  done_ = 0;
}

void ProgressLog::add(double work) {
  const std::lock_guard lock(mutex_);
  done_ += work;
}

void ProgressLog::log_every_second() {
  std::unique_lock lock(mutex_);
  while (!stopping_.wait_for(lock, kLineEvery, [this] { return stop_; })) {
    const std::string text = line(phase_.empty() ? what_ : what_ + ", " + phase_, done_, total_, watch_.elapsed_ms() / 1000);
    lock.unlock();  // the reporting threads do not wait on the log's output
    spdlog::info("{}", text);
    lock.lock();
  }
}

std::string ProgressLog::line(const std::string& what, double done, double total, double elapsed_s) {
  const double share = total > 0 ? std::clamp(done / total, 0.0, 1.0) : 0.0;
  const int filled = static_cast<int>(std::lround(share * kBarWidth));
  std::string text = fmt::format("{} [{}{}] {:3.0f} %, {:.1f} s", what, std::string(static_cast<std::size_t>(filled), '#'),
                                 std::string(static_cast<std::size_t>(kBarWidth - filled), '.'), 100 * share, elapsed_s);
  if (share > 0 && share < 1) text += fmt::format(", about {:.0f} s left", elapsed_s * (1 - share) / share);
  return text;
}

}  // namespace cohaptic
