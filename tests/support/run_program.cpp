#include "support/run_program.h"

#include <sys/wait.h>

#include <array>
#include <cstdio>

namespace cohaptic::testing {

ProgramRun run_program(const std::string& program, const std::string& arguments, bool with_stderr) {
  const std::string command = program + " " + arguments + (with_stderr ? " 2>&1" : " 2>/dev/null");
  ProgramRun result;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return result;
  std::array<char, 4096> buffer{};
  std::size_t n = 0;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
    result.out.append(buffer.data(), n);
  const int status = ::pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

}  // namespace cohaptic::testing
