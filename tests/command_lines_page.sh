#!/usr/bin/env bash
# docs/command-lines.md: every program's and every cohaptic-lab subcommand's --help, as the
# built programs print it, so that the reference cannot drift from them. `make command-lines`
# writes the page; the test CommandLines.ThePageIsWhatTheProgramsSay fails when the page
# differs from what this prints (--check PAGE). The programs run with HOME=~ and no
# XDG_CACHE_HOME, so that a default under the user's home reads ~/... on every machine.
#   usage: tests/command_lines_page.sh BUILD_DIR [--check PAGE]
set -euo pipefail
build=${1:?usage: tests/command_lines_page.sh BUILD_DIR [--check PAGE]}
if [[ ${2:-} == --check ]]; then
  page=${3:?usage: tests/command_lines_page.sh BUILD_DIR --check PAGE}
  if ! diff -u "$page" <("$0" "$build"); then
    echo "command_lines_page: $page is not what the programs print (- the page, + the programs); write it again: make command-lines"
    exit 1
  fi
  echo "command_lines_page: $page is what the programs print"
  exit 0
fi
programs=("server/cohaptic-server" "client/cohaptic-client" "lab/cohaptic-lab" "client/cohaptic-bridge-example")
for program in "${programs[@]}"; do
  [[ -x "$build/$program" ]] || { echo "command_lines_page: no $build/$program (build it: make build)" >&2; exit 2; }
done

# One program's help in a fenced block, its path as typed by a user (the bare name).
help_block() {  # program path, arguments...
  local path=$1 name
  shift
  name=$(basename "$path")
  echo '```text'
  env -u XDG_CACHE_HOME HOME='~' "$path" "$@" --help | sed "s|$path|$name|g"
  echo '```'
}

cat <<'HEADER'
# Command lines

Every program's options as its `--help` prints them: `make command-lines` writes this page
from the built programs, and a test fails when it differs from them. How to use each
program, with examples: [programs](programs.md); from a checkout to a session:
[getting started](getting-started.md).
HEADER
for program in "${programs[@]}"; do
  echo
  echo "## \`$(basename "$program")\`"
  echo
  help_block "$build/$program"
  if [[ $program == lab/cohaptic-lab ]]; then
    subcommands=$("$build/$program" --help | sed -n '/^Subcommands:/,$p' | awk '/^  [a-z]/ { print $1 }')
    for subcommand in $subcommands; do
      echo
      echo "### \`cohaptic-lab $subcommand\`"
      echo
      help_block "$build/$program" "$subcommand"
    done
  fi
done
