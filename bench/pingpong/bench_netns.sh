#!/usr/bin/env bash
# The two-process round trip (bench_pingpong --processes) with ping and pong on two network
# namespaces joined by a veth pair (10.78.0.1 and 10.78.0.2): the samples cross a network
# interface, over UDP, as between two machines. Needs root; leaves nothing behind.
#   bash bench/pingpong/bench_netns.sh [BUILD_DIR] [bench_pingpong options...]
set -euo pipefail
build=$(cd "${1:-$(dirname "$0")/../../build}" && pwd)
shift || true
[ "$(id -u)" = 0 ] || { echo "bench_netns: needs root (network namespaces)" >&2; exit 2; }
a=dyadbench_a_$$ b=dyadbench_b_$$
cleanup() {
  for ns in $a $b; do
    ip netns pids $ns 2>/dev/null | xargs -r kill -9 2>/dev/null || true
    ip netns del $ns 2>/dev/null || true
  done
}
trap cleanup EXIT
ip netns add $a
ip netns add $b
ip link add veth_$$ netns $a type veth peer name veth_$$ netns $b
ip -n $a addr add 10.78.0.1/24 dev veth_$$
ip -n $b addr add 10.78.0.2/24 dev veth_$$
for ns in $a $b; do
  ip -n $ns link set lo up
  ip -n $ns link set veth_$$ up
  ip -n $ns route add 224.0.0.0/4 dev veth_$$  # multicast discovery across the pair
done
ip netns exec $a "$build/bin/bench_pingpong" --processes --pong-prefix "ip netns exec $b" "$@"
