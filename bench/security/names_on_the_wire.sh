#!/usr/bin/env bash
# What a secured graph names on the wire (docs/security.md, "Names on the wire"): a two-process
# graph over UDP on loopback, placed on a host of its own, captured as root for SECONDS while it
# runs: secured alone, secured with a stranger (`dyad echo` with an identity of another CA, over
# and over, for the whole run), and unsecured. For each, the frames captured, those naming the
# graph, a process or the host (any of them, then each), and those naming a topic (the topic
# names travel in the permissions document of every handshake).
# usage: sudo bash bench/security/names_on_the_wire.sh [DYAD] [SECONDS]   (build/bin/dyad, 8 s)
set -euo pipefail
here=$(cd "$(dirname "$0")/../.." && pwd)
dyad=$(realpath "${1:-$here/build/bin/dyad}")
seconds=${2:-8}
[ "$(id -u)" = 0 ] || { echo "names_on_the_wire: capturing loopback needs root" >&2; exit 2; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
tag=$$
graph=hush$tag pa=alpha$tag pb=bravo$tag host=lab$tag topic=cursor$tag
domain=$((100 + tag % 100))

# graph FILE NAME KEYSTORE: the graph (no security without KEYSTORE).
write_graph() {
  {
    echo "graph: $2"
    echo "domain_id: $domain"
    echo "network: {transport: udp, hosts: {$host: 127.0.0.1}}"
    [ -n "$3" ] && echo "security: {keystore: $3}"
    echo "processes:"
    echo "  $pa: {host: $host}"
    echo "  $pb: {host: $host}"
    echo "components:"
    echo "  src: {type: counter_source, rate_hz: 50, process: $pa, outputs: {out: $topic}}"
    echo "  sink: {type: counter_sink, trigger: in, process: $pb, params: {file: $tmp/sink.txt}, inputs: {in: $topic}}"
  } > "$1"
}
write_graph "$tmp/secured.yaml" "$graph" "$tmp/keys"
write_graph "$tmp/open.yaml" "$graph" ""
write_graph "$tmp/stranger.yaml" "stranger$tag" "$tmp/stranger_keys"
"$dyad" security init "$tmp/keys" --graph "$tmp/secured.yaml" > "$tmp/init.log"
"$dyad" security init "$tmp/stranger_keys" --graph "$tmp/stranger.yaml" > "$tmp/init_stranger.log"

# measure LABEL GRAPH STRANGER(0/1)
measure() {
  python3 "$here/tests/capture_marker.py" "$graph,$pa,$pb,$host" "$seconds" > "$tmp/names.txt" &
  local names=$!
  python3 "$here/tests/capture_marker.py" "$topic" "$seconds" > "$tmp/topic.txt" &
  local topics=$!
  sleep 1
  "$dyad" run "$2" --host "$host" --duration $((seconds - 2)) --quiet > "$tmp/run.out" 2> "$tmp/run.err" &
  local run=$!
  if [ "$3" = 1 ]; then
    local end=$((SECONDS + seconds - 2))
    while [ $SECONDS -lt $end ]; do
      "$dyad" echo "$topic" --graph "$tmp/stranger.yaml" --host "$host" --count 1 --wait 2 > /dev/null 2>&1 || true
    done
  fi
  wait $run || { echo "names_on_the_wire: the run failed:" >&2; cat "$tmp/run.err" >&2; exit 1; }
  wait $names $topics
  printf '%-26s %s; %s; samples received %s' "$1:" \
    "$(grep '^packets' "$tmp/names.txt" | sed 's/packets \([0-9]*\) marked/frames \1, naming the graph, a process or the host:/')" \
    "$(sed -n 's/^packets.*marked \([0-9]*\)/naming the topic: \1/p' "$tmp/topic.txt")" "$(wc -l < "$tmp/sink.txt")"
  echo " ($(sed -n 's/^marker //p' "$tmp/names.txt" | tr '\n' ' ' | sed 's/ $//'))"
  rm -f "$tmp/sink.txt"
}
measure "secured" "$tmp/secured.yaml" 0
measure "secured, with a stranger" "$tmp/secured.yaml" 1
measure "unsecured" "$tmp/open.yaml" 0
