#!/usr/bin/env bash
# The last line of every page in docs/results/: the commit, the date and the machine its
# figures were measured on, so that a reader can tell a page's age and where it ran. Each
# page's command ends by appending it (`make results` regenerates them all).
#   usage: tests/results_stamp.sh
set -euo pipefail
source_dir=$(cd "$(dirname "$0")/.." && pwd)
# Dirty only for changes outside docs/results/: `make results` rewrites those pages as it goes.
if commit=$(git -C "$source_dir" describe --always 2>/dev/null); then
  [[ -z $(git -C "$source_dir" status --porcelain -- . ':!docs/results') ]] ||
    commit+=" with uncommitted changes"
else
  commit="no git checkout"
fi
cpu=$(grep -m1 'model name' /proc/cpuinfo 2>/dev/null | cut -d: -f2 | sed 's/^ *//' || true)
echo
echo "_Measured at commit ${commit} on $(date -u +%Y-%m-%d), ${cpu:-an unknown CPU}, $(nproc) cores, $(uname -sr)._"
