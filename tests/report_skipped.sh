#!/usr/bin/env bash
# Lists the tests the last ctest run in BUILD_DIR skipped, each with the reason it gave
# (GTEST_SKIP's message, or a script's "NAME: skipped: why" line: what is missing and the
# command that gets it). `make test` runs it after the suite, so a skipped test is never silent.
set -euo pipefail
log="${1:?usage: tests/report_skipped.sh BUILD_DIR}/Testing/Temporary/LastTest.log"
[[ -f "$log" ]] || exit 0
skipped=$(awk '
  / Skipped$/ { getline reason; next }
  /^\[  SKIPPED \] [^ ]+ \(/ { printf "  %s: %s\n", $4, reason; reason = "" }
  /^[a-z]+: skipped: / { print "  " $0 }' "$log" | sort -u)
[[ -z "$skipped" ]] || printf '%s test(s) skipped:\n%s\n' "$(wc -l <<<"$skipped")" "$skipped"
