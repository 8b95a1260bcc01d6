#!/usr/bin/env bash
# A two-host lab on one machine: two network namespaces joined by a veth pair, so a
# cohaptic-server and its clients talk over a real (virtual) link with its own addresses,
# and `tc netem` can delay, jitter and drop packets on it the way a wide-area network would.
#
#   host "server": namespace cohaptic-srv, address 10.77.0.1/24 on veth end cohaptic-srv
#   host "client": namespace cohaptic-cli, address 10.77.0.2/24 on veth end cohaptic-cli
#
# Usage (as root; needs iproute2):
#   deploy/netns-lab.sh up [--delay-ms D] [--jitter-ms J] [--loss PERCENT]
#        create the lab; with netem options, delay each direction by D ms (+- J ms) and drop
#        PERCENT % of the packets. If the kernel has no netem (sch_netem), says so and leaves
#        the link undelayed: use the server's own --shift-delay-ms/--jitter-ms/--loss instead.
#   deploy/netns-lab.sh run server|client COMMAND [ARGS...]
#        run a command on one host, e.g.
#          deploy/netns-lab.sh run server build/server/cohaptic-server --scene scenes/cube.yaml --listen 10.77.0.1:7400
#          deploy/netns-lab.sh run client build/client/cohaptic-client --server 10.77.0.1:7400 --user A --device script:tests/data/devices/press.yaml
#        (give both a --key-file made by `build/lab/cohaptic-lab keygen FILE` off a trusted
#        network; the lab tools themselves, cohaptic-lab, need no namespace)
#   deploy/netns-lab.sh status      the namespaces, addresses, queueing disciplines and a ping
#   deploy/netns-lab.sh down        remove the lab (also what `up` does first)
#
# Environment: LAB_PREFIX (default cohaptic) names the namespaces and veth ends, so two
# labs can coexist; LAB_SUBNET (default 10.77.0) their /24.
set -euo pipefail

prefix=${LAB_PREFIX:-cohaptic}
subnet=${LAB_SUBNET:-10.77.0}
server_ns="$prefix-srv"
client_ns="$prefix-cli"
server_if="${prefix:0:11}-srv"  # interface names are at most 15 characters
client_if="${prefix:0:11}-cli"

usage() { sed -n '2,24p' "$0" | sed 's/^# \{0,1\}//'; }
fail() { echo "netns-lab: $*" >&2; exit 1; }

need_root_and_iproute() {
  [[ $(id -u) -eq 0 ]] || fail "needs root (network namespaces): run it with sudo"
  command -v ip >/dev/null || fail "needs the ip command: apt-get install iproute2"
}

lab_down() {
  ip netns del "$server_ns" 2>/dev/null || true  # deleting a namespace removes its veth end and the peer
  ip netns del "$client_ns" 2>/dev/null || true
}

# netem on one veth end; returns non-zero if the kernel refuses it.
apply_netem() {
  local ns=$1 iface=$2
  shift 2
  ip netns exec "$ns" tc qdisc replace dev "$iface" root netem "$@" 2>/dev/null
}

lab_up() {
  local delay="" jitter="" loss=""
  while [[ $# -gt 0 ]]; do
    case $1 in
      --delay-ms) delay=${2:?--delay-ms needs a value}; shift 2 ;;
      --jitter-ms) jitter=${2:?--jitter-ms needs a value}; shift 2 ;;
      --loss) loss=${2:?--loss needs a value (percent)}; shift 2 ;;
      *) fail "unknown option '$1' for up (see --help)" ;;
    esac
  done
  for value in $delay $jitter $loss; do
    [[ $value =~ ^[0-9]+(\.[0-9]+)?$ ]] || fail "'$value' is not a non-negative number"
  done
  [[ -n $jitter && -z $delay ]] && fail "--jitter-ms needs --delay-ms"
  lab_down
  ip netns add "$server_ns"
  ip netns add "$client_ns"
  ip link add "$server_if" type veth peer name "$client_if"
  ip link set "$server_if" netns "$server_ns"
  ip link set "$client_if" netns "$client_ns"
  ip -n "$server_ns" addr add "$subnet.1/24" dev "$server_if"
  ip -n "$client_ns" addr add "$subnet.2/24" dev "$client_if"
  for ns in "$server_ns" "$client_ns"; do ip -n "$ns" link set lo up; done
  ip -n "$server_ns" link set "$server_if" up
  ip -n "$client_ns" link set "$client_if" up
  echo "netns-lab: host server = namespace $server_ns ($subnet.1), host client = namespace $client_ns ($subnet.2)"

  if [[ -n $delay || -n $loss ]]; then
    local netem=()
    [[ -n $delay ]] && netem+=(delay "${delay}ms")
    [[ -n $jitter ]] && netem+=("${jitter}ms")
    [[ -n $loss ]] && netem+=(loss "${loss}%")
    if apply_netem "$server_ns" "$server_if" "${netem[@]}" && apply_netem "$client_ns" "$client_if" "${netem[@]}"; then
      echo "netns-lab: tc netem on both ends: ${netem[*]} (each direction)"
    else
      echo "netns-lab: this kernel has no tc netem (sch_netem): the link is NOT delayed." >&2
      echo "netns-lab: inject the delay in cohaptic instead: cohaptic-server --shift-delay-ms ${delay:-0} --jitter-ms ${jitter:-0} --loss $(awk "BEGIN{print ${loss:-0}/100}")" >&2
    fi
  fi
}

lab_status() {
  for ns in "$server_ns" "$client_ns"; do
    ip netns list | grep -q "^$ns\b" || fail "no lab (namespace $ns is missing): run up first"
    echo "== $ns"
    ip -n "$ns" -brief addr show
    ip netns exec "$ns" tc qdisc show | grep -v "dev lo" | sed 's/ *$//' || true
  done
  if command -v ping >/dev/null; then
    ip netns exec "$client_ns" ping -c 3 -i 0.2 "$subnet.1" | tail -n 2
  else
    echo "(no ping installed: apt-get install iputils-ping to measure the link's round trip)"
  fi
}

case ${1:-} in
  up) need_root_and_iproute; shift; lab_up "$@" ;;
  down) need_root_and_iproute; lab_down; echo "netns-lab: removed" ;;
  status) need_root_and_iproute; lab_status ;;
  run)
    need_root_and_iproute
    host=${2:-}
    shift 2 || fail "run needs a host (server or client) and a command"
    [[ $# -gt 0 ]] || fail "run needs a command"
    case $host in
      server) exec ip netns exec "$server_ns" "$@" ;;
      client) exec ip netns exec "$client_ns" "$@" ;;
      *) fail "unknown host '$host': server or client" ;;
    esac
    ;;
  -h | --help | help) usage ;;
  *) usage >&2; exit 2 ;;
esac
