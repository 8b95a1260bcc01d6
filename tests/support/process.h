// Helpers for end-to-end tests: the built programs, scratch directories, and the
// ChildProcess of the lab library.
#pragma once

#include <filesystem>
#include <string>

#include "lab/child_process.h"

namespace cohaptic::testing {

using cohaptic::ChildProcess;
using cohaptic::listening_port;

/// A fresh directory under the test temp dir.
std::filesystem::path scratch_directory(const std::string& name);

/// Path of a built program (server or client).
std::string server_program();
std::string client_program();

}  // namespace cohaptic::testing
