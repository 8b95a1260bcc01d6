#!/usr/bin/env bash
# tests/retry_if_host_stole.sh: a pass passes once; a failure stands when the host took
# nothing; with any steal counted as the host's (STEAL_PERCENT_ALLOWED=-1) a failure is run
# again, at most three runs in all, and a run that then passes passes.
set -uo pipefail
retry=$(dirname "$0")/retry_if_host_stole.sh
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
failed=0
expect() {  # description, expected status, expected runs, command...
  local what=$1 status=$2 runs=$3
  shift 3
  : > "$scratch/runs"
  "$@" 2> "$scratch/stderr"
  local got=$? counted
  counted=$(wc -l < "$scratch/runs")
  if ((got != status || counted != runs)); then
    echo "FAIL: $what: status $got (expected $status), $counted runs (expected $runs)"
    cat "$scratch/stderr"
    failed=1
  else
    echo "ok: $what"
  fi
}
# A program that counts its runs and fails (status 3) until its run number reaches $1.
cat > "$scratch/flaky" <<'PROGRAM'
#!/usr/bin/env bash
echo run >> "$(dirname "$0")/runs"
(( $(wc -l < "$(dirname "$0")/runs") >= $1 )) || exit 3
PROGRAM
chmod +x "$scratch/flaky"
expect "a pass runs once" 0 1 "$retry" "$scratch/flaky" 1
expect "a failure with no steal counted stands" 3 1 env STEAL_PERCENT_ALLOWED=100 "$retry" "$scratch/flaky" 2
expect "a failure under steal runs again, and passes" 0 2 env STEAL_PERCENT_ALLOWED=-1 "$retry" "$scratch/flaky" 2
expect "three failures under steal fail" 3 3 env STEAL_PERCENT_ALLOWED=-1 "$retry" "$scratch/flaky" 9
grep -q "the failure above may be the host's" "$scratch/stderr" || { echo "FAIL: no word of the retry"; failed=1; }
exit $failed
