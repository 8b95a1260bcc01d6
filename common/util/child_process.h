// ChildProcess: a program started with arguments, its stdout and stderr captured to a
// log file, waited for with a timeout, signalled, and killed if still running when it is
// destroyed. The study runner starts servers and clients with it; so do the tests.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace cohaptic {

class ChildProcess {
 public:
  /// Starts `program` with `arguments`; stdout and stderr go to `log`. Throws Error.
  ChildProcess(const std::string& program, const std::vector<std::string>& arguments,
               const std::filesystem::path& log);
  ~ChildProcess();  ///< kills it if still running
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  /// Exit status (128 + signal if it was killed), or nullopt if still running after `timeout`.
  std::optional<int> wait(std::chrono::milliseconds timeout);
  void signal(int signal);
  bool running();
  /// The process id (for /proc), while it runs.
  pid_t pid() const { return pid_; }
  std::string log_text() const;
  /// Waits until the log contains `text`; false on timeout or if the process ended first.
  bool wait_for_log(const std::string& text, std::chrono::milliseconds timeout);

 private:
  pid_t pid_ = -1;
  std::optional<int> status_;
  std::filesystem::path log_;
};

/// The port in a server's "listening on HOST:PORT" log line, or -1.
int listening_port(const std::string& log_text);

}  // namespace cohaptic
