#include "support/process_usage.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <system_error>

namespace cohaptic::testing {

std::optional<ProcessUsage> usage_of(pid_t pid) {
  const std::filesystem::path proc = std::filesystem::path("/proc") / std::to_string(pid);
  std::ifstream status(proc / "status");
  ProcessUsage usage;
  bool found_rss = false;
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("VmRSS:", 0) != 0) continue;
    usage.rss_bytes = std::stoull(line.substr(6)) * 1024;  // "VmRSS:	  12345 kB"
    found_rss = true;
  }
  if (!found_rss) return std::nullopt;
  std::error_code error;
  for (std::filesystem::directory_iterator fd(proc / "fd", error), end; !error && fd != end;
       fd.increment(error))
    ++usage.open_fds;
  if (error) return std::nullopt;
  // stat: "pid (comm) state ..." with utime and stime the 12th and 13th fields after comm,
  // which may itself hold spaces: count from its closing parenthesis.
  std::ifstream stat(proc / "stat");
  std::string text((std::istreambuf_iterator<char>(stat)), std::istreambuf_iterator<char>());
  const std::size_t after_name = text.rfind(')');
  if (after_name == std::string::npos) return std::nullopt;
  std::istringstream fields(text.substr(after_name + 1));
  std::string field;
  unsigned long long utime = 0, stime = 0;
  for (int k = 1; k <= 13 && fields >> field; ++k)
    if (k == 12)
      utime = std::stoull(field);
    else if (k == 13)
      stime = std::stoull(field);
  usage.cpu_seconds =
      static_cast<double>(utime + stime) / static_cast<double>(sysconf(_SC_CLK_TCK));
  return usage;
}

}  // namespace cohaptic::testing
