#include "support/process.h"

#include <unistd.h>

namespace cohaptic::testing {

std::filesystem::path scratch_directory(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) /
                                    ("cohaptic-" + name + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

std::string server_program() { return std::string(COHAPTIC_BINARY_DIR) + "/server/cohaptic-server"; }
std::string client_program() { return std::string(COHAPTIC_BINARY_DIR) + "/client/cohaptic-client"; }

::testing::AssertionResult wait_for_output(ChildProcess& process, const std::string& text,
                                           std::chrono::milliseconds timeout) {
  const auto shown = [&] { return process.log_text().find(text) != std::string::npos; };
  bool ended = false;
  ::testing::AssertionResult waited = wait_until(
      [&] {
        if (shown()) return true;
        ended = !process.running();
        return ended;
      },
      "'" + text + "' in a child process's output", timeout);
  if (shown()) return ::testing::AssertionSuccess();
  if (ended)
    return ::testing::AssertionFailure() << "the child process ended (status " << *process.wait(timeout)
                                         << ") before its output showed '" << text << "'; its output:\n"
                                         << process.log_text();
  return waited << "; its output:\n" << process.log_text();
}

}  // namespace cohaptic::testing
