#include "support/process_usage.h"

#include <filesystem>
#include <fstream>
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
  for (std::filesystem::directory_iterator fd(proc / "fd", error), end; !error && fd != end; fd.increment(error))
    ++usage.open_fds;
  if (error) return std::nullopt;
  return usage;
}

}  // namespace cohaptic::testing
