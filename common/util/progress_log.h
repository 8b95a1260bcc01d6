// ProgressLog: a long task's progress on the log, for a person watching the terminal. From
// the task's first second on, once a second, a line with what it is doing, a bar, the share
// done, the time spent and the time left (from the rate so far; none while nothing is
// counted done yet); nothing for a task that ends within its first second. Its own thread
// writes the lines, so that a step that reports nothing for a while (a factorisation) still
// shows the time going on; any thread may report (a mutex guards the counts). A part that
// reports only when it ends (begin_part, then add) moves the bar meanwhile at the rate the
// machine is expected to reach for it, never past the part's own end.
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
  /// The total work, in any unit (flops, columns); done so far starts at 0, and the rate
  /// for the time left is counted from now.
  void set_total(double total);
  /// `work` more of it is done; ends the part begun, if any.
  void add(double work);
  /// A part of `work` starts now that reports nothing until it ends (a factorisation),
  /// expected to run at `work_per_s` (0: it shows no progress until it ends).
  void begin_part(double work, double work_per_s);

  /// The work shown as done `part_elapsed_s` [s] into a part of `part_work` that began after
  /// `done`, at `expected_rate`: short of the part's end until it reports it.
  static double shown_done(double done, double part_work, double expected_rate,
                           double part_elapsed_s);
  /// The line for `done` of `total` after `elapsed_s` [s] in all and `counting_s` [s] since
  /// the total was set: bar, per cent, time spent, and time left at the rate since then.
  static std::string line(const std::string& what, double done, double total, double elapsed_s,
                          double counting_s);

 private:
  void log_every_second();

  std::string what_, phase_;
  Stopwatch watch_;
  std::mutex mutex_;
  std::condition_variable stopping_;
  bool stop_ = false;
  double total_ = 0, done_ = 0;
  double part_work_ = 0, part_rate_ = 0;
  Stopwatch total_watch_, part_watch_;
  std::thread logger_;  // last: it starts once the rest is ready
};

}  // namespace cohaptic
