#!/usr/bin/env bash
# Runs the fuzz targets of a libFuzzer build (cmake -DCOHAPTIC_FUZZ=ON, as `make fuzz`
# configures it) for a bounded time each, FUZZ_JOBS at once, and prints per target the
# executions, executions per second, the coverage reached (edges, "cov") and libFuzzer's
# features ("ft"), and the new inputs found.
#   tests/fuzz/run_fuzzers.sh BUILD_DIR [TARGET...]      (default: every target)
# Environment: FUZZ_SECONDS per target (default 15), FUZZ_JOBS targets at once (default 2),
# FUZZ_OUT (default out/fuzz).
# Each target starts from its seed corpus (tests/fuzz/corpus/NAME, read only; with the
# dictionary tests/fuzz/NAME.dict if there is one) and from what
# earlier runs found (FUZZ_OUT/NAME/corpus, where new inputs go). An input that crashes,
# breaks a property, leaks, runs longer than 10 s or needs more than 2 GB is written to
# FUZZ_OUT/NAME/ and fails the run (exit 1) after every target has run; fix the bug and
# add the input to tests/fuzz/corpus/NAME/ as regression-<what>, where `make test` replays it.
set -uo pipefail
cd "$(dirname "$0")/../.."
build=${1:?usage: $0 BUILD_DIR [TARGET...]}
shift
seconds=${FUZZ_SECONDS:-15}
parallel=${FUZZ_JOBS:-2}
out=${FUZZ_OUT:-out/fuzz}
if [[ $# -gt 0 ]]; then
  targets=("$@")
else
  mapfile -t targets < <(find tests/fuzz/corpus -mindepth 1 -maxdepth 1 -type d -printf '%f\n' | sort)
fi

export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1}

# One target's run; its exit status goes to FUZZ_OUT/NAME/status.
fuzz_one() {
  local target=$1 program="$build/tests/fuzz/fuzz_$1" dictionary=()
  mkdir -p "$out/$target/corpus"
  [[ -f "tests/fuzz/$target.dict" ]] && dictionary=(-dict="tests/fuzz/$target.dict")
  "$program" "${dictionary[@]}" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
    -artifact_prefix="$out/$target/" "$out/$target/corpus" "tests/fuzz/corpus/$target" >"$out/$target/fuzz.log" 2>&1
  echo $? >"$out/$target/status"
}

failed=()
for target in "${targets[@]}"; do
  if [[ ! -x "$build/tests/fuzz/fuzz_$target" ]]; then
    echo "run_fuzzers: $build/tests/fuzz/fuzz_$target is missing (build the fuzz_targets target first)" >&2
    failed+=("$target")
    continue
  fi
  while [[ $(jobs -rp | wc -l) -ge $parallel ]]; do wait -n; done
  fuzz_one "$target" &
done
wait

printf '%-15s %12s %10s %8s %8s %6s  %s\n' target executions exec/s cov ft new result
for target in "${targets[@]}"; do
  log="$out/$target/fuzz.log"
  [[ -f "$out/$target/status" ]] || continue
  status=$(cat "$out/$target/status")
  rm -f "$out/$target/status"
  final_stat() { sed -n "s/^stat::$1: *//p" "$log" | tail -n 1; }
  coverage=$(grep -E '^#[0-9]+.* cov: ' "$log" | tail -n 1)
  cov=$(sed -n 's/.* cov: \([0-9]*\).*/\1/p' <<<"$coverage")
  ft=$(sed -n 's/.* ft: \([0-9]*\).*/\1/p' <<<"$coverage")
  result=ok
  if [[ $status -ne 0 ]]; then
    result="FAILED (exit $status): see $log"
    failed+=("$target")
  fi
  printf '%-15s %12s %10s %8s %8s %6s  %s\n' "$target" "$(final_stat number_of_executed_units)" "$(final_stat average_exec_per_sec)" \
    "${cov:-?}" "${ft:-?}" "$(final_stat new_units_added)" "$result"
done
if [[ ${#failed[@]} -gt 0 ]]; then
  echo "run_fuzzers: findings in: ${failed[*]}" >&2
  for target in "${failed[@]}"; do
    [[ -f "$out/$target/fuzz.log" ]] && grep -E 'ERROR|SUMMARY|property violated|Test unit written' "$out/$target/fuzz.log" | head -n 5 >&2
  done
  exit 1
fi
