#!/usr/bin/env bash
# Writes to stdout the brain scene (scenes/brain.yaml: its tissue, support, skull and tools)
# with another mesh, its file paths made absolute so that the copy may live anywhere.
#
# Usage: deploy/brain-scene-with-mesh.sh MESH.msh > scene.yaml
#   e.g. deploy/brain-scene-with-mesh.sh scenes/brain/brain.msh (make brain-convergence uses it)
set -euo pipefail
[[ $# -eq 1 && -f $1 ]] || { echo "usage: deploy/brain-scene-with-mesh.sh MESH.msh > scene.yaml (an existing mesh)" >&2; exit 2; }
root=$(cd "$(dirname "$0")/.." && pwd)
sed -e "s#file: brain/[^ ]*\\.msh#file: $(realpath "$1")#" \
    -e "s#surface: brain/inner_skull.asc#surface: $root/scenes/brain/inner_skull.asc#" "$root/scenes/brain.yaml"
