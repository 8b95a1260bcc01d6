// Helpers for end-to-end tests: the built programs, scratch directories, the ChildProcess
// of the lab library, and waiting for a line in a child's output.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "common/util/child_process.h"
#include "support/wait.h"

namespace cohaptic::testing {

using cohaptic::ChildProcess;
using cohaptic::listening_port;

/// A fresh directory under the test temp dir, removed when the test that made it passes
/// (kept, and named on stdout, when it fails).
std::filesystem::path scratch_directory(const std::string& name);

/// Path of a built program (server or client).
std::string server_program();
std::string client_program();

/// Waits (wait_until) until `process`'s output (stdout and stderr) contains `text`. The
/// failure says what was awaited, whether the process ended first, and its output.
::testing::AssertionResult wait_for_output(ChildProcess& process, const std::string& text,
                                           std::chrono::milliseconds timeout = kPatience);

/// A session on loopback in `dir`: cohaptic-server serving `scene` on port 0 with
/// `server_arguments` after its report (server.json), recording (server.mcap) and log
/// (server.log); one cohaptic-client per (user, trajectory), in slots 0, 1, ..., with a
/// scripted device and its report, recording and log named after the user; then the
/// clients' ends, and the server's on SIGINT, each asserted to exit 0. `load_timeout`: how
/// long the server may take to listen (a cold compliance cache takes long).
void run_scripted_session(const std::filesystem::path& dir, const std::filesystem::path& scene,
                          const std::vector<std::string>& server_arguments,
                          const std::vector<std::pair<std::string, std::filesystem::path>>& users,
                          std::chrono::milliseconds load_timeout = kPatience);

}  // namespace cohaptic::testing
