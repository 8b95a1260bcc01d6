// StepFailures: what the simulation loop does about steps that throw. It counts them (in
// all, and in a row), decides which to log so that a repeating or flapping error cannot
// flood the log (the first failure, then at most one line per kStepFailureLogInterval
// with the count since the last line), and says when kMaxConsecutiveStepFailures in a row end the
// session. Pure bookkeeping, on the simulation thread; times: ns of any monotonic clock.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace cohaptic {

/// Failed steps in a row that end the session: at 1 kHz a tenth of a second of nothing but
/// failures, long past any transient (a tool passing through a degenerate contact).
inline constexpr int kMaxConsecutiveStepFailures = 100;
/// At most one log line per this interval about failing steps, after the first.
inline constexpr std::int64_t kStepFailureLogInterval_ns = 1'000'000'000;

class StepFailures {
 public:
  /// A step failed at `now_ns` with `what`. Returns the line to log now, or nullopt if the
  /// failure is only counted (paced).
  std::optional<std::string> failed(std::int64_t now_ns, const std::string& what);
  /// A step succeeded: a run of failures, if any, ends.
  void succeeded() { consecutive_ = 0; }

  /// kMaxConsecutiveStepFailures steps in a row failed: the session should end.
  bool limit_reached() const { return consecutive_ >= kMaxConsecutiveStepFailures; }
  std::uint64_t total() const { return total_; }
  int consecutive() const { return consecutive_; }
  const std::string& last_error() const { return last_error_; }

 private:
  std::uint64_t total_ = 0;
  int consecutive_ = 0;
  std::uint64_t since_logged_ = 0;  ///< failures since the last line, this one included
  std::optional<std::int64_t> last_logged_ns_;
  std::string last_error_;
};

}  // namespace cohaptic
