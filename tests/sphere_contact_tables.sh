#!/usr/bin/env bash
# The sphere contact model's cost beside the naive dense solve, measured in the same run
# (tests/bench_sphere_contact.cpp): runs cohaptic_bench's BM_Sphere benchmarks once and
# prints, as Markdown, the page docs/results/sphere-contact-speed.md holds: (1) the client's
# haptic tick at about 50, 200, 400 and 700 nodes in contact, the incremental solve on the
# IR's normal compliance beside the dense one; (2) the server's state solve at 400, the
# incremental one beside the condensed one,
# and the whole simulation step. Means are Google Benchmark's wall time per call, p99 the
# 99th percentile of the calls' wall times; on a loaded machine both grow, so the load
# average is printed first. The first run meshes the block and solves its compliance
# (about a minute, cached on disk); later runs take about a minute in all.
#
# Usage: tests/sphere_contact_tables.sh [path/to/cohaptic_bench]   (make bench-sphere builds and runs it)
set -euo pipefail
bench=${1:-build/tests/cohaptic_bench}
[[ -x "$bench" ]] || { echo "sphere_contact_tables: no benchmark program at $bench (build it: make build)" >&2; exit 2; }
command -v jq >/dev/null || { echo "sphere_contact_tables: needs jq (deploy/install-deps.sh installs it)" >&2; exit 2; }

json=$("$bench" --benchmark_filter='^BM_Sphere' --benchmark_format=json)
cat <<'HEADER'
# Sphere contact: speed

`make bench-sphere > docs/results/sphere-contact-speed.md` writes this page
(`tests/bench_sphere_contact.cpp`, `tests/sphere_contact_tables.sh`). A 20 mm sphere presses
`scenes/block/block.geo` graded to 0.4 mm, moving a little every tick. The client's tick: the
incremental solve on the IR's normal compliance W, its active set and factor kept from tick
to tick, beside the dense one, which forms the working set's normal compliance from the 3x3
blocks of the condensed compliance every tick and factors it afresh in every pass. The
server's state solve: the incremental one over the users' patches, beside the condensed one
(the working set condensed over B, M_CC inverted, the problem solved afresh). Means are wall
time per call; p99 the 99th percentile of the calls. See
[the sphere contact model](../sphere-contact.md).

HEADER
echo "load average: $(cut -d' ' -f1-3 /proc/loadavg) on $(nproc) cores; $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//')"
echo
jq -r '
  def micro($b; $field): ($b[$field]) as $v
    | if $b.time_unit == "ns" then $v / 1000 elif $b.time_unit == "ms" then $v * 1000
      elif $b.time_unit == "s" then $v * 1e6 else $v end;
  def fmt: if . >= 100 then (. | round | tostring) elif . >= 10 then ((. * 10 | round) / 10 | tostring)
           else ((. * 100 | round) / 100 | tostring) end;
  def ms: . / 1000 | fmt;
  def sci: if . == 0 then "0" else (log10 | floor) as $e | "\((. / pow(10; $e) * 10 | round) / 10)e\($e)" end;
  def failed($b): $b == null or ($b.error_occurred // false);
  def why($b): if $b == null then "not run" else "error: \($b.error_message)" end;
  [.benchmarks[].name | select(startswith("BM_SphereTick/incremental/")) | ltrimstr("BM_SphereTick/incremental/")] as $sizes
  | [.benchmarks[] | {key: (.name | sub("/iterations:[0-9]+$"; "")), value: .}] | from_entries as $b
  | "| nodes in contact | candidates | incremental tick, mean µs | p99 µs | dense tick, mean µs | p99 µs | speed-up (mean) | forces differ by |",
    "|---|---|---|---|---|---|---|---|",
    ( $sizes[] as $n
      | $b["BM_SphereTick/incremental/" + $n] as $i
      | $b["BM_SphereTick/dense/" + $n] as $d
      | if failed($i) or failed($d) then "| ~\($n) | \(why(if failed($i) then $i else $d end)) | | | | | | |"
        else "| \($i.contacts) | \($i.candidates) | \(micro($i; "real_time") | fmt) | \($i.p99_us | fmt) | \(micro($d; "real_time") | fmt) | \($d.p99_us | fmt) | \(micro($d; "real_time") / micro($i; "real_time") | round)× | \($d.difference | sci) |"
        end ),
    ( [$sizes[] | $b["BM_SphereTick/incremental/" + .] | select(failed(.) | not) | .unresolved] | add // 0
      | if . > 0 then "", "\(.) incremental ticks ran past the work budget (kSphereSolveWork): their force was zero." else empty end ),
    "",
    "| server, 400 in contact | candidates | mean ms | p99 ms |",
    "|---|---|---|---|",
    ( [["incremental", "state solve, incremental (SphereStateSolve)"],
       ["condensed", "state solve, condensed"],
       ["simulation", "whole Simulation::step, incremental"]][] as [$kind, $title]
      | $b["BM_SphereStep/" + $kind + "/400"] as $s
      | if failed($s) then "| \($title) | \(why($s)) | | |"
        else "| \($title)\(if $s.rebuilt != null then " (IR rebuilt in \($s.rebuilt * 100 | round) % of steps)" else "" end) | \($s.candidates) | \(micro($s; "real_time") | ms) | \($s.p99_us | ms) |"
        end ),
    ( $b["BM_SphereStep/incremental/400"] as $i | $b["BM_SphereStep/condensed/400"] as $c
      | if failed($i) or failed($c) then empty
        else "", "State solve speed-up (mean): \(micro($c; "real_time") / micro($i; "real_time") | round)×, at \($i.contacts) nodes in contact; the forces of the two states differ by \($c.difference | sci) (relative)."
        end )
' <<<"$json"
"$(dirname "$0")/results_stamp.sh"
