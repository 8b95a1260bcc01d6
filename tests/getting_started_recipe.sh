#!/usr/bin/env bash
# The test GettingStarted.TheRecipeRunsAsWritten: docs/getting-started.md's section "Your own
# scene from your own mesh", run as a reader would type it, in a scratch directory:
#   - each fenced block whose info string names a file (```yaml file=organ.yaml) is saved
#     as that file;
#   - each ```sh block runs, in order, in one bash with -euo pipefail.
# Only the ports change (the page's 7400 and 7480 become free ones), and the verdict of
# `cohaptic-lab summarize` is printed, not failed (exit 3 is UNHEALTHY): the unit tests
# running beside this one on a small machine make haptic deadlines slip, which the verdict
# rightly reports. Every other command must succeed: the mesh, the probe, the session, the
# bit-for-bit replays. Exit 77 (CTest's skip) without gmsh.
#   usage: tests/getting_started_recipe.sh SOURCE_DIR BUILD_DIR
set -euo pipefail
source_dir=${1:?usage: getting_started_recipe.sh SOURCE_DIR BUILD_DIR}
build_dir=${2:?usage: getting_started_recipe.sh SOURCE_DIR BUILD_DIR}
page="$source_dir/docs/getting-started.md"
if ! command -v gmsh >/dev/null; then
  echo "recipe: skipped: no gmsh (the Debian package gmsh; deploy/install-deps.sh installs it)"
  exit 77
fi

work=$(mktemp -d "${TMPDIR:-/tmp}/cohaptic-getting-started-XXXXXX")
keep_on_failure() {
  local status=$?
  if [[ $status -eq 0 ]]; then rm -rf "$work"; else echo "recipe: failed (exit $status); its directory is kept: $work"; fi
}
trap keep_on_failure EXIT

# The section's blocks: files into $work, commands into $work/recipe.sh.
awk -v dir="$work" '
  /^## / { in_section = ($0 == "## Your own scene from your own mesh"); next }
  !in_section { next }
  /^```/ && !fence {
    fence = 1; info = substr($0, 4); target = ""
    if (match(info, /file=[^ ]+/)) target = dir "/" substr(info, RSTART + 5, RLENGTH - 5)
    else if (info == "sh") target = dir "/recipe.sh"
    if (target != "" && target !~ /recipe\.sh$/) { printf "" > target; files++ }
    if (target ~ /recipe\.sh$/) blocks++
    next
  }
  /^```/ && fence { fence = 0; if (target != "") close(target); next }
  fence && target != "" { print >> target }
  END { printf "recipe: %d files, %d command blocks\n", files, blocks > "/dev/stderr" }
' "$page"
for file in organ.geo organ.yaml surgeon_a.yaml surgeon_b.yaml recipe.sh; do
  [[ -s "$work/$file" ]] || { echo "recipe: the page gave no $file: its section changed shape"; exit 1; }
done

port=$((20000 + RANDOM % 20000))
sed -i "s/127\.0\.0\.1:7400/127.0.0.1:$port/g; s/127\.0\.0\.1:7480/127.0.0.1:$((port + 1))/g" "$work/recipe.sh"

cd "$work"
export PATH="$build_dir/server:$build_dir/client:$build_dir/lab:$PATH"
export XDG_CACHE_HOME="$work/cache"  # the compliance cache, not the user's
cohaptic-lab() {
  local status=0
  command cohaptic-lab "$@" || status=$?
  if [[ $1 == summarize && $status -eq 3 ]]; then
    echo "recipe: the verdict is UNHEALTHY (printed, not failed)"
    return 0
  fi
  return $status
}
export -f cohaptic-lab
bash -euo pipefail recipe.sh

for output in organ.msh server.json alice.json bob.json report.json server.mcap alice.mcap bob.mcap; do
  [[ -s $output ]] || { echo "recipe: no $output after the recipe"; exit 1; }
done
grep -q "live view at http://127.0.0.1:$((port + 1))/" server.log || { echo "recipe: the live view did not start"; exit 1; }
echo "recipe: every step ran as written"
