// Child processes for end-to-end tests: the real server and client programs, started with
// arguments, their stderr captured to a file, waited for with a timeout, killed if needed.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace cohaptic::testing {

class ChildProcess {
 public:
  /// Starts `program` with `arguments`; stdout and stderr go to `log`.
  ChildProcess(const std::string& program, const std::vector<std::string>& arguments, const std::filesystem::path& log);
  ~ChildProcess();  ///< kills it if still running
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  /// Exit status, or nullopt if it is still running after `timeout`.
  std::optional<int> wait(std::chrono::milliseconds timeout);
  void signal(int signal);
  bool running();
  std::string log_text() const;
  /// Waits until the log contains `text`; false on timeout or if the process ended.
  bool wait_for_log(const std::string& text, std::chrono::milliseconds timeout);

 private:
  pid_t pid_ = -1;
  std::optional<int> status_;
  std::filesystem::path log_;
};

/// The port in the server's "listening on HOST:PORT" log line.
int listening_port(const std::string& log_text);

/// A fresh directory under the test temp dir.
std::filesystem::path scratch_directory(const std::string& name);

/// Path of a built program (server or client).
std::string server_program();
std::string client_program();

}  // namespace cohaptic::testing
