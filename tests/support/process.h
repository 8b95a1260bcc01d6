// Helpers for end-to-end tests: the built programs, scratch directories, the ChildProcess
// of the lab library, and waiting for a line in a child's output.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <string>

#include "common/util/child_process.h"
#include "support/wait.h"

namespace cohaptic::testing {

using cohaptic::ChildProcess;
using cohaptic::listening_port;

/// A fresh directory under the test temp dir.
std::filesystem::path scratch_directory(const std::string& name);

/// Path of a built program (server or client).
std::string server_program();
std::string client_program();

/// Waits (wait_until) until `process`'s output (stdout and stderr) contains `text`. The
/// failure says what was awaited, whether the process ended first, and its output.
::testing::AssertionResult wait_for_output(ChildProcess& process, const std::string& text,
                                           std::chrono::milliseconds timeout = kPatience);

}  // namespace cohaptic::testing
