// Running a built program to its end from a test: its exit code and what it printed.
#pragma once

#include <string>

namespace cohaptic::testing {

struct ProgramRun {
  int exit_code = -1;  ///< -1 if it could not be started or did not exit normally
  std::string out;     ///< stdout, and stderr after it when asked for
};

/// Runs `program arguments` through the shell (arguments are not quoted) and waits for it.
ProgramRun run_program(const std::string& program, const std::string& arguments,
                       bool with_stderr = false);

}  // namespace cohaptic::testing
