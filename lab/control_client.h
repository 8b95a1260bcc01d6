// ControlClient: a program's line into a running server's control socket (cohaptic-server
// --control, docs/server.md "Switching conditions"): one JSON command out, its one-line
// JSON answer back, blocking. Not thread-safe; one per thread.
#pragma once

#include <asio.hpp>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

namespace cohaptic {

class ControlClient {
 public:
  /// Connects to the socket at `path`; throws Error naming it when it cannot.
  explicit ControlClient(const std::filesystem::path& path);

  /// Sends `line` (a newline is added) and returns the answer parsed. Throws Error when the
  /// connection fails or the answer is not JSON.
  nlohmann::json ask_line(const std::string& line);
  nlohmann::json ask(const nlohmann::json& command) { return ask_line(command.dump()); }
  /// Switches the condition served to `name`, or to the one after the condition served now;
  /// returns the answer ({"served", "switches", "time_s"}), or throws Error with the
  /// server's "error" when it refused.
  nlohmann::json serve(const std::string& name);
  nlohmann::json serve_next();

 private:
  nlohmann::json obey(const nlohmann::json& command);

  std::filesystem::path path_;
  asio::io_context io_;
  asio::local::stream_protocol::socket socket_;
  asio::streambuf input_;
};

}  // namespace cohaptic
