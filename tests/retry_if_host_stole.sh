#!/usr/bin/env bash
# Runs an end-to-end test program (CTest's launcher for the sessions in real time:
# tests/CMakeLists.txt) and, if it fails while the host of this virtual machine held the
# CPUs back, runs it again. Steal time (/proc/stat) is CPU time the host gave another guest:
# a haptic loop and its bare timer floor then miss deadlines together, an IR comes late, a
# measured delay grows, and the test's real-time judgement is the host's, not cohaptic's.
# A failure is retried, at most twice, only when the host took more than a twentieth of the
# CPUs' time during the failed run; it says so on stderr. Any other failure stands.
#   usage: tests/retry_if_host_stole.sh PROGRAM [ARGUMENTS...]
# STEAL_PERCENT_ALLOWED (5 by default) sets the share; its own test sets -1 (always retry).
set -uo pipefail
readonly attempts=3 steal_percent_allowed=${STEAL_PERCENT_ALLOWED:-5}
ticks_per_second=$(getconf CLK_TCK)
cpus=$(nproc)
stolen_ticks() { awk '/^cpu / { print $9 }' /proc/stat 2>/dev/null || echo 0; }
now_ms() { date +%s%3N; }
for ((attempt = 1; ; ++attempt)); do
  steal_from=$(stolen_ticks)
  from_ms=$(now_ms)
  "$@"
  status=$?
  ((status == 0)) && exit 0
  stolen_ms=$((($(stolen_ticks) - steal_from) * 1000 / ticks_per_second))
  wall_ms=$(($(now_ms) - from_ms))
  if ((attempt == attempts || stolen_ms * 100 <= steal_percent_allowed * wall_ms * cpus)); then
    exit "$status"
  fi
  echo "retry_if_host_stole: the host held the $cpus CPUs back for $stolen_ms ms of this" \
    "run's $wall_ms ms (steal time, over ${steal_percent_allowed} % of their time): the failure" \
    "above may be the host's; attempt $((attempt + 1)) of $attempts" >&2
done
