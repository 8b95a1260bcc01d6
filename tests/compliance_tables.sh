#!/usr/bin/env bash
# The compliance of every row node of the brain by its two routes, measured in the same run
# (tests/bench_compliance_routes.cpp): runs cohaptic_bench's BM_BrainRowCompliance
# benchmarks once and prints, as Markdown, the page docs/results/compliance-speed.md holds.
# Each route runs once per mesh (a few minutes in all: the solves of the finest mesh are the
# slow part); the load average is printed first.
#
# Usage: tests/compliance_tables.sh [path/to/cohaptic_bench]   (make bench-compliance builds and runs it)
set -euo pipefail
bench=${1:-build/tests/cohaptic_bench}
[[ -x "$bench" ]] || { echo "compliance_tables: no benchmark program at $bench (build it: make build)" >&2; exit 2; }
command -v jq >/dev/null || { echo "compliance_tables: needs jq (deploy/install-deps.sh installs it)" >&2; exit 2; }

json=$(OPENBLAS_NUM_THREADS=1 "$bench" --benchmark_filter='^BM_BrainRowCompliance' --benchmark_format=json)
cat <<'HEADER'
# Compliance: speed

`make bench-compliance > docs/results/compliance-speed.md` writes this page
(`tests/bench_compliance_routes.cpp`, `tests/compliance_tables.sh`). The compliance columns
of every row node of the brain (its whole surface: the scene has the skull as an obstacle),
by two routes in the same run: one CHOLMOD solve per group of 4 row nodes on one thread
(`ComplianceColumns`, what on-demand compliance does), and the Schur-complement route
(`common/fem/schur_compliance.h`: one factorisation with the row dofs ordered last, then the
inverse of its trailing block by LAPACK's dtrtri and dlauum, BLAS on 2 threads). Times
are wall time; peak memory is the process's resident high-water mark during the run; the
result is the dense block of 3 x row nodes squared doubles. Both routes run on the BLAS
kernels OpenBLAS picks for the CPU, or those `OPENBLAS_CORETYPE` names; the line below says
which. See [the compliance cache](../compliance-cache.md).

HEADER
echo "load average: $(cut -d' ' -f1-3 /proc/loadavg) on $(nproc) cores; $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//'); OpenBLAS's $(jq -r '.context.blas_kernels // "unknown"' <<<"$json") kernels"
echo
jq -r '
  def secs($b): $b.real_time as $v
    | if $b.time_unit == "ms" then $v / 1000 elif $b.time_unit == "us" then $v / 1e6 elif $b.time_unit == "ns" then $v / 1e9 else $v end;
  def fmt: if . >= 100 then (. | round | tostring) elif . >= 10 then ((. * 10 | round) / 10 | tostring)
           else ((. * 100 | round) / 100 | tostring) end;
  def failed($b): $b == null or ($b.error_occurred // false);
  def why($b): if $b == null then "not run" else "error: \($b.error_message)" end;
  ([.benchmarks[].name | capture("mesh:(?<m>[0-9]+)").m] | unique) as $meshes
  | [.benchmarks[] | {key: (.name | sub("/iterations:[0-9]+/real_time$"; "")), value: .}] | from_entries as $b
  | "| mesh | nodes | row nodes | solves, s | row nodes/s | Schur, s | row nodes/s | speed-up | result MB | peak MB (solves, Schur) |",
    "|---|---|---|---|---|---|---|---|---|---|",
    ( $meshes[] as $m
      | $b["BM_BrainRowCompliance/route:0/mesh:" + $m] as $s
      | $b["BM_BrainRowCompliance/route:1/mesh:" + $m] as $schur
      | if failed($s) or failed($schur) then "| \($m) | \(why(if failed($s) then $s else $schur end)) | | | | | | | | |"
        else "| \($s.label) | \($s.nodes) | \($s.row_nodes) | \(secs($s) | fmt) | \($s.row_nodes_per_s | fmt) | \(secs($schur) | fmt) | \($schur.row_nodes_per_s | fmt) | \(secs($s) / secs($schur) | fmt)× | \($schur.columns_MB | round) | \($s.peak_MB | round), \($schur.peak_MB | round) |"
        end )
' <<<"$json"
"$(dirname "$0")/results_stamp.sh"
