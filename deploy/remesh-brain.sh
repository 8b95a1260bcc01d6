#!/usr/bin/env bash
# Regenerates scenes/brain/brain.msh, the coarse tetrahedral mesh of the Colin27 brain,
# and scenes/brain/brain_graded.msh, the mesh graded towards the tools, from the
# public-domain surface in ../shared/data/colin27 (see scenes/brain/README.md).
#
# A maintenance tool, not part of the build: the generated meshes are committed (all but
# the reference mesh below, which is too big).
# Needs gmsh (4.8; Debian 12's `gmsh` package) and python3 (for the surface step).
#
#   deploy/remesh-brain.sh [DATA_DIR] [OUTPUT]
#     DATA_DIR  holds brain_surface.asc (default: ../shared/data/colin27 next to the repository)
#     OUTPUT    the mesh to write (default: scenes/brain/brain.msh; with GRADED=1,
#               scenes/brain/brain_graded.msh; with REFINE, it must be given)
#   H=8 deploy/remesh-brain.sh          another element size in mm (default 9, see remesh.geo);
#                                       in the graded mode, the size far from the tools
#   CORRIDOR=0 deploy/remesh-brain.sh   the plain surface, without the corridor (below)
#   GRADED=1 deploy/remesh-brain.sh     the graded mesh, brain_graded.msh: size FINE in the
#                                       tools' working region (both 7 mm spheres swept along
#                                       their press paths) and within MARGIN mm of it,
#                                       growing linearly to H over the next GROW mm; size
#                                       NEAR within NEAR_MARGIN mm of the swept spheres, where
#                                       the tips touch, growing to FINE over NEAR_GROW mm
#   GRADED=1 REFINE=2 deploy/remesh-brain.sh ../shared/data/colin27 out/brain_reference.msh
#                                       the convergence reference: FINE and NEAR divided by
#                                       REFINE, the regions and H unchanged
#   FINE=2.5 NEAR=1.2 MARGIN=20 GROW=30 NEAR_MARGIN=3 NEAR_GROW=5
#                                       the graded mode's sizes and regions, mm (the defaults)
#
# Steps:
#  1. python3 reads the FreeSurfer surface and writes it as STL. Unless CORRIDOR=0, it first
#     opens the supracerebellar corridor: the atlas surface is a smooth envelope with no gap
#     between the cerebellum and the occipital lobes, so there is no surface on which a tool
#     could push the cerebellum down or the occipital lobe up. A V-shaped cleft is carved
#     into the back of the envelope along the crease between them (the level of the
#     tentorium): surface points near the plane z = -42 mm are moved anteriorly (+y) by up
#     to 20 mm at the plane, falling linearly to 0 at z = -42 +- 12 mm, over |x| < 30 mm,
#     tapering smoothly to nothing at |x| = 50 mm, and only behind y = -35 mm (fully
#     behind y = -75 mm). The map is one-to-one, so the surface stays closed and free of
#     self-intersections; its lower wall faces up (the cerebellum's side) and its upper
#     wall faces down (the occipital lobes' side).
#  2. gmsh runs remesh.geo (classify, reparametrise, remesh at size h or graded from
#     FINE to h, tetrahedralise).
#  3. The $Parametrizations section is dropped: nothing reads it, and it would triple the file.
set -euo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
data=${1:-$repo/../shared/data/colin27}
graded=${GRADED:-0}
refine=${REFINE:-1}
if [[ $graded == 0 ]]; then
  out=${2:-$repo/scenes/brain/brain.msh}
elif [[ $refine == 1 ]]; then
  out=${2:-$repo/scenes/brain/brain_graded.msh}
else
  [[ $# -ge 2 ]] || { echo "remesh-brain: REFINE=$refine needs DATA_DIR and OUTPUT" >&2; exit 1; }
  out=$2
fi
geo=$repo/scenes/brain/remesh.geo
asc=$data/brain_surface.asc

command -v gmsh >/dev/null || { echo "remesh-brain: gmsh not found (apt-get install gmsh)" >&2; exit 1; }
command -v python3 >/dev/null || { echo "remesh-brain: python3 not found" >&2; exit 1; }
[[ -r $asc ]] || { echo "remesh-brain: cannot read $asc" >&2; exit 1; }

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# FreeSurfer ASCII surface -> ASCII STL. Layout: a comment line; "<vertices> <triangles>";
# the vertices "x y z 0"; the triangles "i j k 0" with 0-based indices.
python3 - "$asc" "$work/brain_surface.stl" "${CORRIDOR:-1}" <<'PY'
import sys
src, dst, corridor = sys.argv[1], sys.argv[2], sys.argv[3] != "0"
with open(src) as f:
    lines = f.read().split("\n")
nv, nt = map(int, lines[1].split()[:2])
V = [tuple(map(float, l.split()[:3])) for l in lines[2:2 + nv]]
T = [tuple(map(int, l.split()[:3])) for l in lines[2 + nv:2 + nv + nt]]
if len(V) != nv or len(T) != nt:
    sys.exit(f"{src}: expected {nv} vertices and {nt} triangles")

if corridor:
    # The supracerebellar corridor (see the header). Lengths in mm.
    ZC, DEPTH, HALF = -42.0, 20.0, 12.0  # cleft plane, depth at the plane, half height
    X_FULL, X_NONE = 30.0, 50.0           # full depth for |x| < X_FULL, none beyond X_NONE
    Y_FULL, Y_NONE = -75.0, -35.0         # full depth behind Y_FULL, none in front of Y_NONE

    def smoothstep(t):
        t = min(1.0, max(0.0, t))
        return t * t * (3.0 - 2.0 * t)

    def carve(p):
        x, y, z = p
        tent = max(0.0, 1.0 - abs(z - ZC) / HALF)
        across = 1.0 - smoothstep((abs(x) - X_FULL) / (X_NONE - X_FULL))
        behind = 1.0 - smoothstep((y - Y_FULL) / (Y_NONE - Y_FULL))
        # y -> y + DEPTH*tent*across*behind(y) is increasing in y (DEPTH * 1.5 / 40 < 1),
        # so the map is one-to-one.
        return (x, y + DEPTH * tent * across * behind, z)

    V = [carve(p) for p in V]

with open(dst, "w") as f:
    f.write("solid brain\n")
    for a, b, c in T:
        A, B, C = V[a], V[b], V[c]
        u = [B[k] - A[k] for k in range(3)]
        v = [C[k] - A[k] for k in range(3)]
        n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
        l = sum(x * x for x in n) ** 0.5 or 1.0
        f.write(" facet normal %.6e %.6e %.6e\n  outer loop\n" % tuple(x / l for x in n))
        for P in (A, B, C):
            f.write("   vertex %.6f %.6f %.6f\n" % P)
        f.write("  endloop\n endfacet\n")
    f.write("endsolid brain\n")
PY

cp "$geo" "$work/remesh.geo"
args=()
[[ -n ${H:-} ]] && args+=(-setnumber h "$H")
if [[ $graded != 0 ]]; then
  divide() { awk -v size="$1" -v by="$refine" 'BEGIN { printf "%g", size / by }'; }
  args+=(-setnumber fine "$(divide "${FINE:-2.5}")" -setnumber near "$(divide "${NEAR:-1.2}")")
  [[ -n ${MARGIN:-} ]] && args+=(-setnumber margin "$MARGIN")
  [[ -n ${GROW:-} ]] && args+=(-setnumber grow "$GROW")
  [[ -n ${NEAR_MARGIN:-} ]] && args+=(-setnumber nearMargin "$NEAR_MARGIN")
  [[ -n ${NEAR_GROW:-} ]] && args+=(-setnumber nearGrow "$NEAR_GROW")
fi
(cd "$work" && gmsh remesh.geo "${args[@]}" -3 -nt 1 -format msh41 -o raw.msh > gmsh.log 2>&1) || {
  cat "$work/gmsh.log" >&2; echo "remesh-brain: gmsh failed" >&2; exit 1; }
grep -E "^Info    : [0-9]+ nodes [0-9]+ elements|Warning|Error" "$work/gmsh.log" >&2 || true

# Drop the $Parametrizations section: cohaptic (and Gmsh, to open the mesh) do not need it.
awk '/^\$Parametrizations/{skip=1} !skip{print} /^\$EndParametrizations/{skip=0}' \
  "$work/raw.msh" > "$work/brain.msh"
mkdir -p "$(dirname "$out")"
mv "$work/brain.msh" "$out"
echo "remesh-brain: wrote $out ($(wc -c < "$out") bytes)"
