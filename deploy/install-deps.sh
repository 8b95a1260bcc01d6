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
  # numerics: Eigen, CHOLMOD (SuiteSparse) with OpenBLAS behind it; Boost.Math (headers: the
  # F and studentized range distributions of the paired-comparison analysis)
  libeigen3-dev libsuitesparse-dev libopenblas-dev libboost-dev
  # networking and the wire format (zstd: the IR streams); the live view's web server
  libasio-dev libprotobuf-dev protobuf-compiler libsodium-dev libzstd-dev libwebsocketpp-dev
  # configuration, command line, logging, JSON output
  libyaml-cpp-dev libcli11-dev libspdlog-dev libfmt-dev nlohmann-json3-dev
  # the mass-spring benchmark tables (make bench-thin) read the benchmarks' JSON
  jq
  # tests and benchmarks; the browser the live view's test opens the page in; the mesher
  # of the Hertz study's graded block (scenes/hertz/quarter_block.geo, meshed by the build)
  libgtest-dev libgmock-dev libbenchmark-dev chromium gmsh
  # fuzzing (libFuzzer) and sanitizer reports: make fuzz, make test-asan, make test-tsan;
  # lld, the faster linker every build uses when it is there (cmake/fast_linker.cmake)
  clang libclang-rt-14-dev llvm lld
  # the formatter the test Format.EverySourceFileIsAsClangFormatWritesIt runs (make format)
  clang-format
)

# Node.js and npm, for two test tools only: the official MCAP reader (@mcap/core) a test
# checks our recordings with, and playwright-core, which drives Chromium in the view's
# browser tests (the live view's own libraries ship in view/web/lib; nothing at run time
# needs npm). Debian's packages, unless some Node.js is already there (NodeSource's brings
# its own npm and conflicts with Debian's).
if ! command -v node >/dev/null 2>&1 && ! command -v npm >/dev/null 2>&1; then packages+=(nodejs npm); fi

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  [[ "$status" == "install ok installed" ]] || missing+=("$p")
done

# The test tools, set from deploy/node/package-lock.json (npm ci), so every machine gets
# the same. If npm cannot reach its registry, the tests that need them are skipped, each
# naming the package and the command that gets it; npm's own words are shown here.
install_node_tools() {
  local node_dir
  node_dir="$(cd "$(dirname "$0")" && pwd)/node"
  command -v npm >/dev/null 2>&1 || return 0
  [[ -d "$node_dir/node_modules/@mcap/core" && -d "$node_dir/node_modules/playwright-core" ]] && return 0
  echo "install-deps: npm ci in deploy/node (@mcap/core playwright-core, for the tests)"
  local said
  if ! said=$(npm ci --prefix "$node_dir" --no-audit --no-fund --loglevel=error --fetch-retries=1 \
      --fetch-timeout=30000 2>&1); then
    echo "install-deps: npm ci in deploy/node failed (the tests that need @mcap/core or playwright-core will be skipped); npm said:"
    printf '%s\n' "$said" | grep -v '^\s*$' | head -n 6 | sed 's/^/  /'
  fi
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
