#!/usr/bin/env bash
# Runs the command of a page of docs/results/ that a lab tool writes itself (its --out), then
# names that command at the page's top and stamps its end (tests/results_stamp.sh), as the
# pages a command prints do themselves. The command is shown as typed, but for the program's
# directory (build/lab/cohaptic-lab is shown as cohaptic-lab).
#   usage: tests/results_page.sh PAGE COMMAND [ARGUMENTS...]
set -euo pipefail
(($# >= 2)) || { echo "usage: $0 PAGE COMMAND [ARGUMENTS...]" >&2; exit 2; }
page=$1
shift
"$@"
[[ -f "$page" ]] || { echo "results_page: $* wrote no $page" >&2; exit 1; }
shown=$(basename "$1")
shift
(($# > 0)) && shown+=" $(printf '%q ' "$@")" && shown=${shown% }
said="\`$shown\` writes this page."
# After the page's title if it has one, else at its top.
awk -v said="$said" 'NR == 1 && /^# / { print; print ""; print said; next }
                     NR == 1 { print said; print "" } { print }' "$page" > "$page.new"
tests/results_stamp.sh >> "$page.new"
mv "$page.new" "$page"
