#!/usr/bin/env bash
# Rewrites the seed corpora under tests/fuzz/corpus/ from real files and a real session:
#   - scene, study, gmsh, freesurfer: copies of the repository's scene and study files and
#     of the small test meshes (tests/data/mesh_io);
#   - datagram, control_frames, ir, mcap, bridge, view: taken by fuzz_make_seeds from the
#     recordings of a 4 s, two-user session on the cube (scenes/tradeoff/cube_two_users.yaml,
#     P1, both users pressing) and of a 4 s session of one user pressing the noodle
#     (scenes/thin/noodle.yaml, a mass-spring body) and of one sphere pressing the cube under
#     the sphere contact model (scenes/tradeoff/cube_two_spheres.yaml), run here with the real server and
#     clients on loopback (protocol 3, the development key);
#   - ir also from text_seeds/ir/*.txtpb (protoc --encode): bodies no recorded session has
#     yet (the home-spring and separation bodies), and compliance rows under B truncation
#     (rows_truncated: a held node the IR leaves out).
# Seeds that fuzzing found (crash-*, regression-*) are kept. Run from a configured build:
#   BUILD_DIR=build tests/fuzz/make_seeds.sh
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${BUILD_DIR:-build}
port=${SEED_PORT:-7479}
corpus=tests/fuzz/corpus
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

cmake --build "$build" --target cohaptic-server cohaptic-client fuzz_make_seeds >/dev/null

copy_seeds() {  # target, files...
  local target=$1; shift
  mkdir -p "$corpus/$target"
  find "$corpus/$target" -type f ! -name 'crash-*' ! -name 'regression-*' -delete
  for file in "$@"; do cp "$file" "$corpus/$target/$(basename "$file")"; done
}
copy_seeds scene scenes/cube.yaml scenes/brain.yaml scenes/tradeoff/cube_two_users.yaml scenes/thin/noodle.yaml scenes/thin/noodle_heated.yaml \
  scenes/objects/paired_boxes.yaml scenes/laparoscopy/tissue.yaml scenes/separation/two_layers.yaml
copy_seeds study scenes/studies/*.yaml
copy_seeds gmsh tests/data/mesh_io/*.msh
copy_seeds freesurfer tests/data/mesh_io/*.asc

"$build/server/cohaptic-server" --scene scenes/tradeoff/cube_two_users.yaml --listen "127.0.0.1:$port" --protocol P1 \
  --duration 12 --no-disk-cache --view 127.0.0.1:0 --record "$work/server.mcap" --log-level warn &
server=$!
sleep 6  # the compliance block of the cube's front face
"$build/client/cohaptic-client" --server "127.0.0.1:$port" --user alice --slot 0 --best-effort --duration 4 \
  --device script:scenes/tradeoff/cube_press_slide.yaml --record "$work/client_a.mcap" --log-level warn &
client_a=$!
"$build/client/cohaptic-client" --server "127.0.0.1:$port" --user bob --slot 1 --best-effort --duration 4 \
  --device script:scenes/tradeoff/cube_press_hold.yaml --record "$work/client_b.mcap" --log-level warn
wait "$client_a"
wait "$server"

"$build/server/cohaptic-server" --scene scenes/thin/noodle.yaml --listen "127.0.0.1:$port" --duration 8 \
  --no-disk-cache --log-level warn &
server=$!
sleep 2
"$build/client/cohaptic-client" --server "127.0.0.1:$port" --user carol --slot 0 --best-effort --duration 4 \
  --device script:scenes/thin/noodle/surgeon_a.yaml --record "$work/client_noodle.mcap" --log-level warn
wait "$server"

"$build/server/cohaptic-server" --scene scenes/tradeoff/cube_two_spheres.yaml --listen "127.0.0.1:$port" --duration 10 \
  --no-disk-cache --log-level warn &
server=$!
sleep 4
"$build/client/cohaptic-client" --server "127.0.0.1:$port" --user dave --slot 1 --best-effort --duration 3 \
  --device script:scenes/tradeoff/cube_sphere_press_hold.yaml --record "$work/client_sphere.mcap" --log-level warn
wait "$server"

for target in datagram control_frames ir mcap bridge view; do
  mkdir -p "$corpus/$target"
  find "$corpus/$target" -type f ! -name 'crash-*' ! -name 'regression-*' -delete
done
"$build/tests/fuzz/fuzz_make_seeds" "$work/server.mcap" "$work/client_b.mcap" "$work/client_noodle.mcap" "$work/client_sphere.mcap" \
  "$corpus"
# Bodies no recorded session has yet, written by hand in protobuf text format.
for seed in tests/fuzz/text_seeds/ir/*.txtpb; do
  protoc -Iproto --encode=cohaptic.wire.IntermediateRepresentation proto/cohaptic/messages.proto \
    <"$seed" >"$corpus/ir/$(basename "$seed" .txtpb)"
done
