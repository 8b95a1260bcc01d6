#!/usr/bin/env bash
# The mass-spring body's benchmarks beside the thin-objects paper's Table 2
# (docs/mass-spring.md): runs cohaptic_bench's MassSpring benchmarks once and prints, as
# Markdown, the page docs/results/mass-spring-speed.md holds: (1) the integrator step of the whole tube and the collision search at 180, 360,
# 540 and 720 nodes beside the paper's deformation and collision loops (3.19 GHz Core i5)
# with our speed-up, (2) the largest stable time step at the paper's two densities beside
# its 1.8 and 0.7 ms, (3) a client's haptic tick against the sections it was sent.
# Times are Google Benchmark's CPU time per call, and its wall time beside it: on a loaded
# machine the two differ, so the load average is printed first.
#
# Usage: tests/mass_spring_tables.sh [path/to/cohaptic_bench]   (make bench-thin builds and runs it)
set -euo pipefail
bench=${1:-build/tests/cohaptic_bench}
[[ -x "$bench" ]] || { echo "mass_spring_tables: no benchmark program at $bench (build it: make build)" >&2; exit 2; }
command -v jq >/dev/null || { echo "mass_spring_tables: needs jq (deploy/install-deps.sh installs it)" >&2; exit 2; }

json=$("$bench" --benchmark_filter='^BM_MassSpring' --benchmark_format=json)
cat <<'HEADER'
# Mass-spring objects: speed

`make bench-thin > docs/results/mass-spring-speed.md` writes this page
(`tests/bench_mass_spring.cpp`, `tests/mass_spring_tables.sh`). The tube of the thin-objects
paper: its integrator step and its collision search at 180 to 720 nodes beside the paper's
deformation and collision loops (its Table 2, on a 3.19 GHz Core i5), the largest stable
time step at the paper's two densities (found by power iteration), and a client's haptic
tick against the sections it was sent. Times are CPU time per call, wall time in brackets:
on a loaded machine the two differ. See [mass-spring objects](../mass-spring.md).

HEADER
echo "load average: $(cut -d' ' -f1-3 /proc/loadavg) on $(nproc) cores; $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//')"
echo
jq -r '
  def micro($b; $field): ($b[$field]) as $v
    | if $b.time_unit == "ns" then $v / 1000 elif $b.time_unit == "ms" then $v * 1000 else $v end;
  def fmt: if . >= 100 then (. | round | tostring) elif . >= 10 then ((. * 10 | round) / 10 | tostring)
           else ((. * 100 | round) / 100 | tostring) end;
  [.benchmarks[] | {key: .name, value: .}] | from_entries as $b
  | {"180": [0.19, 4.7], "360": [0.30, 9.8], "540": [0.39, 14.9], "720": [0.50, 19.4]} as $paper
  | "| nodes | integrator step, µs CPU (wall) | paper: deformation loop | speed-up, CPU (wall) | collision, nearest node then faces, µs CPU | naive, every triangle, µs CPU | paper: collision loop |",
    "|---|---|---|---|---|---|---|",
    ( ["180", "360", "540", "720"][] as $n
      | $b["BM_MassSpringDeformation/" + $n] as $d
      | $b["BM_MassSpringCollision/faces/" + $n] as $f
      | $b["BM_MassSpringCollision/all_triangles/" + $n] as $a
      | "| \($n) | \(micro($d; "cpu_time") | fmt) (\(micro($d; "real_time") | fmt)) | \($paper[$n][1]) ms | \($paper[$n][1] * 1000 / micro($d; "cpu_time") | round)× (\($paper[$n][1] * 1000 / micro($d; "real_time") | round)×) | \(micro($f; "cpu_time") | fmt) | \(micro($a; "cpu_time") | fmt) | \($paper[$n][0]) ms |" ),
    "",
    "| density | largest stable time step (360 nodes) | paper |",
    "|---|---|---|",
    "| 9049 kg/m³ | \($b["BM_MassSpringCriticalStep/9049"].critical_ms | fmt) ms | 1.8 ms |",
    "| 1508 kg/m³ | \($b["BM_MassSpringCriticalStep/1508"].critical_ms | fmt) ms | 0.7 ms |",
    "",
    "| free sections a side | nodes in the IR | IR kB | client tick (1 ms integrated, tool pressing), µs CPU (wall) |",
    "|---|---|---|---|",
    ( ["1", "2", "4", "8"][] as $s | $b["BM_MassSpringClientTick/" + $s] as $c
      | "| \($s) | \($c.nodes) | \($c.ir_bytes / 1000 | fmt) | \(micro($c; "cpu_time") | fmt) (\(micro($c; "real_time") | fmt)) |" )
' <<<"$json"
"$(dirname "$0")/results_stamp.sh"
