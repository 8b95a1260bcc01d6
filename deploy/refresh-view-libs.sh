#!/usr/bin/env bash
# The live view's two libraries, shipped in view/web/lib/ so that the view never needs npm
# at run time: three.js (three.module.min.js, OrbitControls.js) and protobufjs
# (protobuf.min.js), each with its licence, the versions (VERSIONS) and the checksums of
# every file (SHA256SUMS).
#
#   deploy/refresh-view-libs.sh          fetch the versions pinned in deploy/view-libs/
#                                        package-lock.json with npm (npm ci), copy them into
#                                        view/web/lib/ and rewrite VERSIONS and SHA256SUMS
#   deploy/refresh-view-libs.sh --check  check the shipped files against SHA256SUMS
#                                        (offline; a test runs it)
#
# To move to another version: change deploy/view-libs/package.json, run
# npm install --prefix deploy/view-libs --package-lock-only, then this script, and commit
# view/web/lib/ with the lock file.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
lib="$root/view/web/lib"

if [[ "${1:-}" == --check ]]; then
  cd "$lib"
  sha256sum --check --quiet --strict SHA256SUMS ||
    { echo "refresh-view-libs: view/web/lib/ does not match its SHA256SUMS (restore it from git, or run deploy/refresh-view-libs.sh)" >&2; exit 1; }
  echo "refresh-view-libs: view/web/lib/ matches SHA256SUMS ($(wc -l <SHA256SUMS) files)"
  exit 0
fi
[[ $# -eq 0 ]] || { echo "usage: deploy/refresh-view-libs.sh [--check]" >&2; exit 2; }

command -v npm >/dev/null 2>&1 || { echo "refresh-view-libs: needs npm (Debian: apt-get install npm)" >&2; exit 1; }
packages="$root/deploy/view-libs"
if ! npm ci --prefix "$packages" --no-audit --no-fund --loglevel=error >"$packages/npm.log" 2>&1; then
  echo "refresh-view-libs: npm ci in deploy/view-libs failed; npm said:" >&2
  head -n 8 "$packages/npm.log" >&2
  exit 1
fi
rm -f "$packages/npm.log"
modules="$packages/node_modules"
mkdir -p "$lib"
cp "$modules/three/build/three.module.min.js" "$lib/three.module.min.js"
cp "$modules/three/examples/jsm/controls/OrbitControls.js" "$lib/OrbitControls.js"
cp "$modules/three/LICENSE" "$lib/LICENSE.three"
cp "$modules/protobufjs/dist/protobuf.min.js" "$lib/protobuf.min.js"
cp "$modules/protobufjs/LICENSE" "$lib/LICENSE.protobufjs"
version() { sed -n 's/^  "version": "\(.*\)",$/\1/p' "$modules/$1/package.json"; }
printf 'three %s\nprotobufjs %s\n' "$(version three)" "$(version protobufjs)" >"$lib/VERSIONS"
cd "$lib"
sha256sum LICENSE.three LICENSE.protobufjs OrbitControls.js protobuf.min.js three.module.min.js VERSIONS >SHA256SUMS
echo "refresh-view-libs: view/web/lib/ holds $(tr '\n' ' ' <VERSIONS)($(du -sh . | cut -f1))"
