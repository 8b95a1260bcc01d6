#include "support/process.h"

#include <fmt/format.h>
#include <signal.h>
#include <unistd.h>

#include <cstdio>
#include <memory>
#include <system_error>

namespace cohaptic::testing {

namespace {

// Removes the scratch directories a test made once it has passed, and names them when it has
// failed, so that a failure's logs and recordings stay for reading while a passing suite
// leaves nothing behind (the soak alone writes about 750 MB).
class ScratchDirectoryCleanup : public ::testing::EmptyTestEventListener {
 public:
  void add(const std::filesystem::path& dir) { directories_.push_back(dir); }

  void OnTestEnd(const ::testing::TestInfo& test) override {
    for (const std::filesystem::path& dir : directories_) {
      if (test.result()->Passed()) {
        std::error_code ignored;
        std::filesystem::remove_all(dir, ignored);
      } else {
        std::printf("kept the failed test's scratch directory %s\n", dir.c_str());
      }
    }
    directories_.clear();
  }

 private:
  std::vector<std::filesystem::path> directories_;
};

ScratchDirectoryCleanup& scratch_directory_cleanup() {
  // GoogleTest owns (and deletes) a listener once it is appended.
  static ScratchDirectoryCleanup* const cleanup = [] {
    auto* listener = new ScratchDirectoryCleanup;
    ::testing::UnitTest::GetInstance()->listeners().Append(listener);
    return listener;
  }();
  return *cleanup;
}

}  // namespace

std::filesystem::path scratch_directory(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) /
                                    ("cohaptic-" + name + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  scratch_directory_cleanup().add(dir);
  return dir;
}

std::string server_program() {
  return std::string(COHAPTIC_BINARY_DIR) + "/server/cohaptic-server";
}
std::string client_program() {
  return std::string(COHAPTIC_BINARY_DIR) + "/client/cohaptic-client";
}

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
    return ::testing::AssertionFailure()
           << "the child process ended (status " << *process.wait(timeout)
           << ") before its output showed '" << text << "'; its output:\n"
           << process.log_text();
  return waited << "; its output:\n" << process.log_text();
}

void run_scripted_session(const std::filesystem::path& dir, const std::filesystem::path& scene,
                          const std::vector<std::string>& server_arguments,
                          const std::vector<std::pair<std::string, std::filesystem::path>>& users,
                          std::chrono::milliseconds load_timeout) {
  std::vector<std::string> arguments = {"--scene",  scene.string(),
                                        "--listen", "127.0.0.1:0",
                                        "--report", (dir / "server.json").string(),
                                        "--record", (dir / "server.mcap").string()};
  arguments.insert(arguments.end(), server_arguments.begin(), server_arguments.end());
  ChildProcess server(server_program(), arguments, dir / "server.log");
  ASSERT_TRUE(wait_for_output(server, "listening on", load_timeout)) << server.log_text();
  const int port = listening_port(server.log_text());
  std::vector<std::unique_ptr<ChildProcess>> clients;
  for (std::size_t slot = 0; slot < users.size(); ++slot) {
    const std::string& user = users[slot].first;
    clients.push_back(std::make_unique<ChildProcess>(
        client_program(),
        std::vector<std::string>{
            "--server", fmt::format("127.0.0.1:{}", port), "--user", user, "--slot",
            std::to_string(slot), "--device", "script:" + users[slot].second.string(), "--report",
            (dir / (user + ".json")).string(), "--record", (dir / (user + ".mcap")).string()},
        dir / (user + ".log")));
  }
  for (const auto& client : clients) ASSERT_EQ(client->wait(kPatience), 0) << client->log_text();
  server.signal(SIGINT);
  ASSERT_EQ(server.wait(kPatience), 0) << server.log_text();
}

}  // namespace cohaptic::testing
