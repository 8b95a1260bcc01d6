#!/usr/bin/env bash
# The brain's forces against a mesh twice as fine where the tools work: both tools pressing
# together, at points along their presses (fractions of the 6 mm press of
# scenes/brain/surgeon_a.yaml and surgeon_b.yaml; the deepest is 1), the skull holding the
# brain as it does in the demo, printed as the Markdown page
# docs/results/brain-convergence.md holds. The shipped meshes are probed through the IR, as
# served (`cohaptic-lab probe`); the reference by the full sparse solve (`--reference`),
# which needs no compliance columns, so that its whole surface (every node may reach the
# skull) costs a factorisation and the columns of the nodes in contact only.
#
# Meshes: scenes/brain/brain.msh (9 mm), scenes/brain/brain_graded.msh (the scene's: 1.2 mm
# where the tips touch, 2.5 mm around them), and the reference, with every graded size
# halved: $REFERENCE, default out/brain_reference.msh, made by `GRADED=1 REFINE=2
# deploy/remesh-brain.sh` when missing (needs gmsh). Compliance caches go to
# out/convergence-cache.
#
# Usage: tests/brain_convergence_table.sh [path/to/cohaptic-lab]   (make brain-convergence runs it)
#   FRACTIONS="0.4 0.7 1" to choose the points (default 0.4 0.6 0.8 1).
set -euo pipefail
cd "$(dirname "$0")/.."
lab=${1:-build/lab/cohaptic-lab}
[[ -x "$lab" ]] || { echo "brain_convergence_table: no cohaptic-lab at $lab (build it: make build)" >&2; exit 2; }
command -v jq >/dev/null || { echo "brain_convergence_table: needs jq (deploy/install-deps.sh installs it)" >&2; exit 2; }
reference=${REFERENCE:-out/brain_reference.msh}
fractions=${FRACTIONS:-0.4 0.6 0.8 1}
if [[ ! -f "$reference" ]]; then
  echo "brain_convergence_table: making the reference mesh $reference (GRADED=1 REFINE=2 deploy/remesh-brain.sh)" >&2
  mkdir -p "$(dirname "$reference")"
  GRADED=1 REFINE=2 deploy/remesh-brain.sh ../shared/data/colin27 "$reference" >&2
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cache=out/convergence-cache
mkdir -p "$cache"

# The demo's scene with each mesh.
deploy/brain-scene-with-mesh.sh scenes/brain/brain.msh >"$work/coarse.yaml"
deploy/brain-scene-with-mesh.sh scenes/brain/brain_graded.msh >"$work/graded.yaml"
deploy/brain-scene-with-mesh.sh "$reference" >"$work/reference.yaml"

# Start (where each tool stops before pressing) and deepest centre of each tool, mm.
a0=(-15.4 -79.9 -45.0); a1=(-15.943 -75.736 -49.285)
b0=(0.9 -89.8 -34.5);   b1=(0.119 -85.715 -30.175)
at() { awk -v f="$1" -v x0="$2" -v y0="$3" -v z0="$4" -v x1="$5" -v y1="$6" -v z1="$7" \
  'BEGIN { printf "%.4f,%.4f,%.4f", x0 + f * (x1 - x0), y0 + f * (y1 - y0), z0 + f * (z1 - z0) }'; }

rows=()
for f in $fractions; do
  a=$(at "$f" "${a0[@]}" "${a1[@]}"); b=$(at "$f" "${b0[@]}" "${b1[@]}")
  for mesh in coarse graded reference; do
    echo "brain_convergence_table: fraction $f on the $mesh mesh ..." >&2
    method=()
    [[ $mesh == reference ]] && method=(--reference)
    "$lab" probe --scene "$work/$mesh.yaml" --tool="$a" --tool="$b" "${method[@]}" --json --cache-dir "$cache" \
      --log-level warn >"$work/$mesh-$f.json"
  done
  rows+=("$f")
done

cat <<'HEADER'
# The brain's forces against a finer mesh

`make brain-convergence > docs/results/brain-convergence.md` writes this page
(`tests/brain_convergence_table.sh`). Both tools press the brain together (the demo's
scene, `scenes/brain.yaml`, skull included, with each mesh in turn), at points along their
presses: the fraction of the 6 mm press of `scenes/brain/surgeon_a.yaml` and `surgeon_b.yaml`
(A meets the tissue at about 0.2, B at once; 1 is the deepest). The shipped meshes' forces
are `cohaptic-lab probe` through the IR, as served; the reference's, `cohaptic-lab probe
--reference`, the full sparse solve of the same unilateral problem. Meshes: `brain.msh`
(9 mm everywhere); `brain_graded.msh`, the scene's (1.2 mm within 3 mm of the tools'
spheres along their presses, 2.5 mm within 20 mm, growing to 9 mm); and the reference, its
graded sizes halved in the same regions (`GRADED=1 REFINE=2 deploy/remesh-brain.sh`). |F| in
mN; the differences are from the reference.

HEADER
echo "| fraction | A: 9 mm | A: graded | A: reference | A: graded − ref. | A: 9 mm − ref. | B: 9 mm | B: graded | B: reference | B: graded − ref. | B: 9 mm − ref. |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"
for f in "${rows[@]}"; do
  jq -r -n --arg f "$f" --slurpfile c "$work/coarse-$f.json" --slurpfile g "$work/graded-$f.json" --slurpfile r "$work/reference-$f.json" '
    def mag(t): (t.force | map(. * .) | add | sqrt) * 1000;
    def pct(a; b): if b == 0 then "—" else "\(((a - b) / b * 1000 | round) / 10) %" end;
    def cell(v): (v * 100 | round) / 100 | tostring;
    [0, 1] | map(. as $k | [mag($c[0].tools[$k]), mag($g[0].tools[$k]), mag($r[0].tools[$k])]) as $m
    | "| \($f) | \(cell($m[0][0])) | \(cell($m[0][1])) | \(cell($m[0][2])) | \(pct($m[0][1]; $m[0][2])) | \(pct($m[0][0]; $m[0][2])) | \(cell($m[1][0])) | \(cell($m[1][1])) | \(cell($m[1][2])) | \(pct($m[1][1]; $m[1][2])) | \(pct($m[1][0]; $m[1][2])) |"'
done
echo
jq -r -n --slurpfile c "$work/coarse-1.json" --slurpfile g "$work/graded-1.json" --slurpfile r "$work/reference-1.json" \
  '"Meshes: \($c[0].nodes), \($g[0].nodes) and \($r[0].nodes) nodes."' 2>/dev/null || true
"$(dirname "$0")/results_stamp.sh"
