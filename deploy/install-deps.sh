#!/usr/bin/env bash
# Installs every Debian 12 package that cohaptic's build, tests and benchmarks need.
#
# Idempotent: when everything is already installed it only checks and exits quickly.
# Needs root (or passwordless sudo) to install; otherwise it lists what is missing
# and exits non-zero.
set -euo pipefail

packages=(
  # toolchain
  build-essential cmake pkg-config git ca-certificates
  # numerics: Eigen, CHOLMOD (SuiteSparse) with OpenBLAS behind it
  libeigen3-dev libsuitesparse-dev libopenblas-dev
  # networking and the wire format (zstd: the IR streams); the live view's web server
  libasio-dev libprotobuf-dev protobuf-compiler libsodium-dev libzstd-dev libwebsocketpp-dev
  # configuration, command line, logging, JSON output
  libyaml-cpp-dev libcli11-dev libspdlog-dev libfmt-dev nlohmann-json3-dev
  # the mass-spring benchmark tables (make bench-thin) read the benchmarks' JSON
  jq
  # tests and benchmarks; the browser the live view's test opens the page in; the mesher
  # of the Hertz study's graded block (scenes/hertz/quarter_block.geo, meshed by the build)
  libgtest-dev libgmock-dev libbenchmark-dev chromium gmsh
  # fuzzing (libFuzzer) and sanitizer reports: make fuzz, make test-asan, make test-tsan
  clang libclang-rt-14-dev llvm
)

# Node.js and npm, for the live view's page libraries (three.js, protobufjs), the official
# MCAP reader (@mcap/core) a test checks our recordings with, and playwright-core, which
# drives Chromium in the view's browser test: Debian's packages, unless some Node.js is
# already there (NodeSource's brings its own npm and conflicts with Debian's).
if ! command -v node >/dev/null 2>&1 && ! command -v npm >/dev/null 2>&1; then packages+=(nodejs npm); fi

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  [[ "$status" == "install ok installed" ]] || missing+=("$p")
done

# npm packages, each set from its lock file (npm ci), so every machine gets the same:
#   view/web     three, protobufjs: the live view's page, served by cohaptic-server --view
#                (no CDN at run time);
#   deploy/node  @mcap/core (the recording-format test), playwright-core (the view's
#                browser test).
# If npm cannot reach its registry: the view cannot serve its page (it says so), and the
# tests that need the others are skipped, saying how to get them.
install_node_tools() {
  local here root
  here="$(cd "$(dirname "$0")" && pwd)"
  root="$(dirname "$here")"
  command -v npm >/dev/null 2>&1 || return 0
  local -A wanted=(
    ["$root/view/web"]="three protobufjs"
    ["$here/node"]="@mcap/core playwright-core"
  )
  local dir package
  for dir in "${!wanted[@]}"; do
    for package in ${wanted[$dir]}; do
      if [[ ! -d "$dir/node_modules/$package" ]]; then
        echo "install-deps: npm ci in ${dir#"$root"/} (${wanted[$dir]})"
        npm ci --prefix "$dir" --no-audit --no-fund --loglevel=error >/dev/null 2>&1 ||
          echo "install-deps: npm ci in ${dir#"$root"/} failed: what needs ${wanted[$dir]} will say so"
        break
      fi
    done
  done
}

if [[ ${#missing[@]} -eq 0 ]]; then
  install_node_tools
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

echo "install-deps: missing ${#missing[@]} package(s): ${missing[*]}"

if [[ $(id -u) -eq 0 ]]; then
  as_root=()
elif command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then
  as_root=(sudo -n)
else
  echo "install-deps: cannot install: not root and no passwordless sudo." >&2
  echo "install-deps: run as root:  apt-get install -y ${missing[*]}" >&2
  exit 1
fi

export DEBIAN_FRONTEND=noninteractive
"${as_root[@]}" apt-get update -q
"${as_root[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
install_node_tools
echo "install-deps: done"
