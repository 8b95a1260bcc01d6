#!/usr/bin/env bash
# The project's C++ sources and headers as clang-format writes them (.clang-format: Google's
# style at 100 columns).
#   tests/format_sources.sh          rewrites every file that differs (make format)
#   tests/format_sources.sh --check  changes nothing; lists each line that differs (file:line)
#                                    and exits 1 if there is one: the test Format.EverySourceFile
# Exit 77 (a skipped test) when clang-format is not installed.
set -euo pipefail
cd "$(dirname "$0")/.."
command -v clang-format >/dev/null 2>&1 || {
  echo "format_sources: clang-format is not installed (Debian: apt-get install clang-format)" >&2
  exit 77
}
mapfile -t files < <(find common proto net server client lab view tests \
  \( -path view/web/lib -o -path tests/fuzz/corpus -o -name 'build*' -o -name node_modules \) -prune -o \
  -type f \( -name '*.cpp' -o -name '*.h' -o -name '*.hpp' \) -print | sort)
[[ ${#files[@]} -gt 100 ]] || { echo "format_sources: found only ${#files[@]} files: run from a checkout" >&2; exit 2; }
if [[ "${1:-}" != --check ]]; then
  clang-format -i "${files[@]}"
  echo "format_sources: ${#files[@]} files formatted"
  exit 0
fi
if ! report=$(clang-format --dry-run --Werror "${files[@]}" 2>&1); then
  lines=$(grep -c 'clang-format-violations' <<<"$report" || true)
  echo "format_sources: $lines place(s) differ from clang-format's (make format rewrites them); the first:"
  grep 'clang-format-violations' <<<"$report" | head -n 40 | sed -E 's/: (warning|error): code should be clang-formatted.*//'
  exit 1
fi
echo "format_sources: ${#files[@]} files as clang-format writes them"
