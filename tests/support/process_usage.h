// What a running process holds, read from Linux's /proc: its resident set (VmRSS, bytes)
// its open file descriptors (the entries of /proc/PID/fd) and its CPU time (/proc/PID/stat). The
// soak samples both for the server and its clients to show that nothing grows with time.
#pragma once

#include <sys/types.h>

#include <cstddef>
#include <optional>

namespace cohaptic::testing {

struct ProcessUsage {
  std::size_t rss_bytes = 0;
  std::size_t open_fds = 0;
  double cpu_seconds = 0;  ///< user and system time used so far, all threads
};

/// `pid`'s usage now; nullopt if it has ended (or /proc cannot be read).
std::optional<ProcessUsage> usage_of(pid_t pid);

}  // namespace cohaptic::testing
