#!/usr/bin/env bash
# The IR bytes of the sphere contact model as they travel, beside M~'s forms:
# runs the two-surgeon demo on the graded block (scenes/block/two_spheres.yaml) with the
# scripted tools (DEMO_DEVICE=script: each sphere exactly where its script puts it, 2 mm
# deep at the deepest, some 400 nodes pushed per IR), then `cohaptic-lab ir-bytes` on
# the two clients' recordings, and prints the Markdown page docs/results/sphere-contact-bytes.md
# holds. About a minute (longer the first time: the scene's compliance is computed at load
# and cached). Environment: BUILD_DIR (default build), DEMO_PORT, OUT (default out/sphere-bytes).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${BUILD_DIR:-build}
out=${OUT:-out/sphere-bytes}
BUILD_DIR=$build DEMO_DEVICE=script DEMO_VIEW_PORT=off DEMO_OUT=$out ./deploy/run-demo.sh scenes/block/two_spheres.yaml >&2
cat <<'HEADER'
# Sphere contact: IR bytes as they travel

`deploy/sphere-contact-bytes.sh > docs/results/sphere-contact-bytes.md` writes this page: two
scripted surgeons press the graded block (`scenes/block/two_spheres.yaml`, 10 mm spheres,
0.6 mm under each) with `make demo`'s scripts, then `cohaptic-lab ir-bytes` reads what each
client received. "As sent" is the IRs as they travelled (each whole, W's upper triangle in
f64, in the connection's zstd stream); "uncompressed" the same IRs alone; the last two are
what the same contacts would cost in the forms the other contact models send,
uncompressed: M̃ whole (three rows per row node, f64) and compliance rows (the rows of the
compliance of the nodes new to the client). See [the sphere contact model](../sphere-contact.md).

HEADER
"$build/lab/cohaptic-lab" ir-bytes --scene scenes/block/two_spheres.yaml "$out/client_a.mcap" "$out/client_b.mcap" \
  --log-level warn
echo
echo "Load average when measured: $(cut -d' ' -f1-3 /proc/loadavg) on $(nproc) cores."
"$(dirname "$0")/../tests/results_stamp.sh"
