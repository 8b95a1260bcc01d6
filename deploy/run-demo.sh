#!/usr/bin/env bash
# The two-surgeon demo on loopback: a cohaptic-server serving a scene (P1; the first
# argument, default scenes/brain.yaml) and two
# cohaptic-client processes whose hand models follow the surgeons' scripted motions (A
# retracts the cerebellum downward, B the occipital lobe upward). About 20 s. Writes
# every report under out/demo/, the three processes' recordings (server.mcap,
# client_a.mcap, client_b.mcap), the deformed brain surface for ParaView under
# out/demo/display/ (open surface.pvd), prints the summary, verifies the clients'
# recordings bit for bit (cohaptic-lab replay --verify), and exits non-zero if the
# session was unhealthy (see docs/reports.md "The verdict and the demo report") or a verification
# failed.
#
# Another scene (e.g. deploy/run-demo.sh scenes/thin/noodle.yaml) takes the surgeons'
# scripts from the directory named after it (scenes/thin/noodle/surgeon_a.yaml, _b.yaml),
# and runs without the display and, unless DEMO_VIEW_PORT is set, the live view (both show
# a scene of one linear elastic object).
#
# The server serves the live view (cohaptic-server --view) on 127.0.0.1:DEMO_VIEW_PORT and
# the demo prints its address: open it in a browser to watch the session. If the view
# cannot serve its page (the port taken, say), the session runs without it and the demo
# says why.
#
# Environment: BUILD_DIR (default build), DEMO_PORT (default 7431; 0: one the system
# chooses), DEMO_DURATION (s, default 20), DEMO_PROTOCOL (P1), DEMO_DEVICE (hand or script),
# DEMO_OUT (out/demo), DEMO_VIEW_PORT (default 7480; 0: one the system chooses; "off": no
# live view), DEMO_IR_FORM (rows or m_tilde, the server's --ir-form; default rows),
# DEMO_VIEW_SCREENSHOT (a PNG file: a headless Chromium
# watches the whole session and takes this screenshot once both surgeons press with 0.01 N;
# the README's picture is taken so), DEMO_WAIT_FOR_BROWSER (1: the surgeons start once a
# browser has connected to the live view, at most 120 s after the server listens).
set -euo pipefail
cd "$(dirname "$0")/.."
scene=${1:-scenes/brain.yaml}
scripts=${scene%.yaml}
[[ -f "$scene" && -f "$scripts/surgeon_a.yaml" && -f "$scripts/surgeon_b.yaml" ]] ||
  { echo "demo: needs $scene and the scripts $scripts/surgeon_a.yaml and $scripts/surgeon_b.yaml" >&2; exit 2; }
display=(--display "${DEMO_OUT:-out/demo}/display" --display-rate-hz 5)
default_view_port=7480
if [[ "$scene" != scenes/brain.yaml ]]; then display=(); default_view_port=off; fi
build=${BUILD_DIR:-build}
port=${DEMO_PORT:-7431}
duration=${DEMO_DURATION:-20}
protocol=${DEMO_PROTOCOL:-P1}
device=${DEMO_DEVICE:-hand}
out=${DEMO_OUT:-out/demo}
view_port=${DEMO_VIEW_PORT:-$default_view_port}
screenshot=${DEMO_VIEW_SCREENSHOT:-}
wait_for_browser=${DEMO_WAIT_FOR_BROWSER:-}
ir_form=${DEMO_IR_FORM:-rows}
server_bin=$build/server/cohaptic-server
client_bin=$build/client/cohaptic-client
lab_bin=$build/lab/cohaptic-lab
mkdir -p "$out"
rm -rf "$out"/*.json "$out"/*.log "$out"/*.mcap "$out"/surgeon_*.yaml "$out/display"

# The surgeons keep moving for the whole session: each plays a copy of its script whose
# `repeat` lasts past the duration even if one pass took a second (the client stops at
# --duration), so someone who opens the live view late still sees them press.
passes=$(awk -v d="$duration" 'BEGIN { n = int(d) + 2; print (n > 100000 ? 100000 : n) }')
for surgeon in surgeon_a surgeon_b; do
  { grep -v '^repeat:' "$scripts/$surgeon.yaml"; echo "repeat: $passes"; } >"$out/$surgeon.yaml"
done

pids=()
cleanup() { for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null || true; done; }
trap cleanup EXIT

view=()
[[ "$view_port" == off ]] || view=(--view "127.0.0.1:$view_port")
# The server outlives the clients (stopped once both are done) so that both can say goodbye.
"$server_bin" --scene "$scene" --listen "127.0.0.1:$port" --protocol "$protocol" --ir-form "$ir_form" \
  --duration $((duration + ${wait_for_browser:+120} + 6)) --report "$out/server.json" --record "$out/server.mcap" "${display[@]}" \
  "${view[@]}" >"$out/server.log" 2>&1 &
pids+=($!)
# A cold start computes the compliance (a minute or more on a busy machine), printing its
# progress every second: wait while the server lives and its log moves.
logged=-1 quiet=0
until grep -q "listening on" "$out/server.log" 2>/dev/null; do
  if ! kill -0 "${pids[0]}" 2>/dev/null; then cat "$out/server.log" >&2; echo "demo: the server failed to start" >&2; exit 1; fi
  size=$(stat -c %s "$out/server.log" 2>/dev/null || echo 0)
  if [[ "$size" == "$logged" ]]; then quiet=$((quiet + 1)); else quiet=0 logged=$size; fi
  ((quiet < 600)) || { echo "demo: the server is not listening and has logged nothing for 60 s" >&2; exit 1; }
  sleep 0.1
done
# The port it listens on (DEMO_PORT=0: one the system chose), and the live view's word.
port=$(sed -n 's/.*listening on [^ ]*:\([0-9][0-9]*\) .*/\1/p' "$out/server.log" | head -n 1)
for _ in $(seq 1 50); do
  [[ ${#view[@]} -eq 0 ]] || grep -q "live view at\|live view off" "$out/server.log" && break
  sleep 0.1
done
echo "demo: server up on 127.0.0.1:$port ($protocol); two surgeons for ${duration} s ..."
# A view that cannot serve its page is off; the session goes on and the summary says why.
view_off=$(sed -n 's/.*live view off: //p' "$out/server.log" | head -n 1)
if [[ -n "$view_off" ]]; then
  echo "demo: the live view is off: $view_off"
elif [[ ${#view[@]} -gt 0 ]]; then
  url=$(sed -n 's/.*live view at \(http[^ ]*\).*/\1/p' "$out/server.log" | head -n 1)
  echo "demo: live view at $url (open it in a browser; replay it afterwards with: $lab_bin replay $out/server.mcap --view 127.0.0.1:$(sed 's#.*:\([0-9]*\)/.*#\1#' <<<"$url"))"
  if [[ -n "$screenshot" ]]; then
    # Chromium draws in software here; at the lowest priority it takes what the haptic
    # loops leave, as a browser on another machine would take nothing (view_check.mjs keeps
    # the Chromium it starts at its own nice value).
    nice -n 19 node tests/support/view_check.mjs --url "$url" --screenshot "$screenshot" --min-force 0.01 --focus-tools 1 --stay "$duration" \
      >"$out/view_check.json" 2>"$out/view_check.log" &
    pids+=($!)
  fi
fi

# A browser started alongside (Chromium's start takes seconds of CPU) watches from the first press.
if [[ -n "$wait_for_browser" && -z "$view_off" && ${#view[@]} -gt 0 ]]; then
  for _ in $(seq 1 1200); do
    grep -q "view: a browser connected" "$out/server.log" && break
    sleep 0.1
  done
fi

"$client_bin" --server "127.0.0.1:$port" --user surgeon-A --slot 0 --device "$device:$out/surgeon_a.yaml" \
  --duration "$duration" --report "$out/client_a.json" --record "$out/client_a.mcap" >"$out/client_a.log" 2>&1 &
pids+=($!)
"$client_bin" --server "127.0.0.1:$port" --user surgeon-B --slot 1 --device "$device:$out/surgeon_b.yaml" \
  --duration "$duration" --report "$out/client_b.json" --record "$out/client_b.mcap" >"$out/client_b.log" 2>&1 &
pids+=($!)
status=0
wait "${pids[-2]}" || status=$?
wait "${pids[-1]}" || status=$?
# Both surgeons have said goodbye: the server stops now (its --duration is the backstop).
kill -INT "${pids[0]}" 2>/dev/null || true
wait "${pids[0]}" || status=$?
if [[ ${#pids[@]} -gt 3 ]]; then
  wait "${pids[1]}" && echo "demo: screenshot of the live view in $screenshot" || echo "demo: no screenshot (see $out/view_check.json)"
fi
pids=()
if [[ $status -ne 0 ]]; then
  tail -n 5 "$out"/*.log >&2
  echo "demo: a process failed (exit $status)" >&2
fi
healthy=0
"$lab_bin" summarize --server-report "$out/server.json" --client-report "$out/client_a.json" \
  --client-report "$out/client_b.json" --out "$out/report.json" || healthy=$?
# Every force each surgeon felt, recomputed from the recorded inputs, must be bit-identical.
# (The server's recording verifies too, re-running every simulation step: cohaptic-lab
# replay out/demo/server.mcap --verify; about 13 s for this 20 s session on 2 cores.)
verified=0
for client in client_a client_b; do
  "$lab_bin" replay "$out/$client.mcap" --verify --log-level warn || verified=1
done
[[ -z "$view_off" ]] || echo "demo: the live view was off: $view_off"
[[ $healthy -eq 0 ]] || exit "$healthy"
exit "$verified"
