#include "common/util/progress_log.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace cohaptic {
namespace {

constexpr std::chrono::seconds kLineEvery{
    1};  // and the first line after it: a shorter task logs nothing
constexpr int kBarWidth = 20;
constexpr double kPartShownAtMost = 0.95;  // of a part's work, until it reports its end

}  // namespace

ProgressLog::ProgressLog(std::string what)
    : what_(std::move(what)), logger_([this] { log_every_second(); }) {}

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
  part_work_ = 0;
  total_watch_ = Stopwatch();
}

void ProgressLog::add(double work) {
  const std::lock_guard lock(mutex_);
  done_ += work;
  part_work_ = 0;
}

void ProgressLog::begin_part(double work, double work_per_s) {
  const std::lock_guard lock(mutex_);
  part_work_ = work;
  part_rate_ = work_per_s;
  part_watch_ = Stopwatch();
}

void ProgressLog::log_every_second() {
  std::unique_lock lock(mutex_);
  while (!stopping_.wait_for(lock, kLineEvery, [this] { return stop_; })) {
    const double done = shown_done(done_, part_work_, part_rate_, part_watch_.elapsed_ms() / 1000);
    const std::string text = line(phase_.empty() ? what_ : what_ + ", " + phase_, done, total_,
                                  watch_.elapsed_ms() / 1000, total_watch_.elapsed_ms() / 1000);
    lock.unlock();  // the reporting threads do not wait on the log's output
    spdlog::info("{}", text);
    lock.lock();
  }
}

double ProgressLog::shown_done(double done, double part_work, double expected_rate,
                               double part_elapsed_s) {
  return done + std::min(kPartShownAtMost * part_work, expected_rate * part_elapsed_s);
}

std::string ProgressLog::line(const std::string& what, double done, double total, double elapsed_s,
                              double counting_s) {
  const double share = total > 0 ? std::clamp(done / total, 0.0, 1.0) : 0.0;
  const int filled = static_cast<int>(std::lround(share * kBarWidth));
  std::string text = fmt::format(
      "{} [{}{}] {:3.0f} %, {:.1f} s", what, std::string(static_cast<std::size_t>(filled), '#'),
      std::string(static_cast<std::size_t>(kBarWidth - filled), '.'), 100 * share, elapsed_s);
  if (share > 0 && share < 1)
    text += fmt::format(", about {:.0f} s left", counting_s * (1 - share) / share);
  return text;
}

}  // namespace cohaptic
