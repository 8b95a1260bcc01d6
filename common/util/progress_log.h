// ProgressLog: a long task's progress on the log, for a person watching the terminal. From
// the task's first second on, once a second, a line with what it is doing, a bar, the share
// done, the time spent and the time left (from the rate so far; none while nothing is
// counted done yet); nothing for a task that ends within its first second. Its own thread
// writes the lines, so that a step that reports nothing for a while (a factorisation) still
// shows the time going on; any thread may report (a mutex guards the counts).
#pragma once

#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>

#include "common/util/stopwatch.h"

namespace cohaptic {

class ProgressLog {
 public:
  /// `what` names the task in each line ("compliance").
  explicit ProgressLog(std::string what);
  ~ProgressLog();  ///< stops its thread
  ProgressLog(const ProgressLog&) = delete;
  ProgressLog& operator=(const ProgressLog&) = delete;

  /// What the task is doing now ("factorising K"), shown after its name.
  void set_phase(std::string phase);
  /// The total work, in any unit (flops, columns); done so far starts at 0.
  void set_total(double total);
  /// `work` more of it is done.
  void add(double work);

  /// The line for `done` of `total` after `elapsed_s` [s]: bar, per cent, time spent, time left.
  static std::string line(const std::string& what, double done, double total, double elapsed_s);

 private:
  void log_every_second();

  std::string what_, phase_;
  Stopwatch watch_;
  std::mutex mutex_;
  std::condition_variable stopping_;
  bool stop_ = false;
  double total_ = 0, done_ = 0;
  std::thread logger_;  // last: it starts once the rest is ready
};

}  // namespace cohaptic
