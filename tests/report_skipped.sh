#!/usr/bin/env bash
# Lists the tests the last ctest run in BUILD_DIR skipped, each with the reason it gave
# (GTEST_SKIP's message: what is missing and the command that gets it). `make test` runs it
# after the suite, so a skipped test is never silent.
set -euo pipefail
log="${1:?usage: tests/report_skipped.sh BUILD_DIR}/Testing/Temporary/LastTest.log"
[[ -f "$log" ]] || exit 0
skipped=$(awk '
  / Skipped$/ { getline reason; next }
  /^\[  SKIPPED \] [^ ]+ \(/ { printf "  %s: %s\n", $4, reason; reason = "" }' "$log" | sort -u)
[[ -z "$skipped" ]] || printf '%s test(s) skipped:\n%s\n' "$(wc -l <<<"$skipped")" "$skipped"
