#!/usr/bin/env bash
# The two-surgeon demo on loopback: a cohaptic-server serving the brain scene (P1) and two
# cohaptic-client processes whose hand models follow the surgeons' scripted motions (A
# retracts the cerebellum downward, B the occipital lobe upward). About 20 s. Writes
# every report under out/demo/, the deformed brain surface for ParaView under
# out/demo/display/ (open surface.pvd), prints the summary, and exits non-zero if the
# session was unhealthy (see README.md, "Reports and the demo report").
#
# Environment: BUILD_DIR (default build), DEMO_PORT (default 7431), DEMO_DURATION (s, default
# 20), DEMO_PROTOCOL (P1), DEMO_DEVICE (hand or script), DEMO_OUT (out/demo).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${BUILD_DIR:-build}
port=${DEMO_PORT:-7431}
duration=${DEMO_DURATION:-20}
protocol=${DEMO_PROTOCOL:-P1}
device=${DEMO_DEVICE:-hand}
out=${DEMO_OUT:-out/demo}
server_bin=$build/server/cohaptic-server
client_bin=$build/client/cohaptic-client
mkdir -p "$out"
rm -rf "$out"/*.json "$out"/*.log "$out/display"

pids=()
cleanup() { for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null || true; done; }
trap cleanup EXIT

# The server outlives the clients by a few seconds so that both can say goodbye.
"$server_bin" --scene scenes/brain.yaml --listen "127.0.0.1:$port" --protocol "$protocol" \
  --duration $((duration + 6)) --report "$out/server.json" --display "$out/display" --display-rate-hz 5 \
  >"$out/server.log" 2>&1 &
pids+=($!)
for _ in $(seq 1 300); do
  grep -q "listening on" "$out/server.log" 2>/dev/null && break
  if ! kill -0 "${pids[0]}" 2>/dev/null; then cat "$out/server.log" >&2; echo "demo: the server failed to start" >&2; exit 1; fi
  sleep 0.1
done
grep -q "listening on" "$out/server.log" || { echo "demo: the server did not start listening" >&2; exit 1; }
echo "demo: server up on 127.0.0.1:$port ($protocol); two surgeons for ${duration} s ..."

"$client_bin" --server "127.0.0.1:$port" --user surgeon-A --slot 0 --device "$device:scenes/brain/surgeon_a.yaml" \
  --duration "$duration" --report "$out/client_a.json" >"$out/client_a.log" 2>&1 &
pids+=($!)
"$client_bin" --server "127.0.0.1:$port" --user surgeon-B --slot 1 --device "$device:scenes/brain/surgeon_b.yaml" \
  --duration "$duration" --report "$out/client_b.json" >"$out/client_b.log" 2>&1 &
pids+=($!)
status=0
wait "${pids[1]}" || status=$?
wait "${pids[2]}" || status=$?
wait "${pids[0]}" || status=$?
pids=()
if [[ $status -ne 0 ]]; then
  tail -n 5 "$out"/*.log >&2
  echo "demo: a process failed (exit $status)" >&2
fi
"$server_bin" summarize --server-report "$out/server.json" --client-report "$out/client_a.json" \
  --client-report "$out/client_b.json" --out "$out/report.json"
