#!/usr/bin/env bash
# ros2.wire_peer_cyclone_loopback: dyad_ros2_wire_peer against itself (Cyclone to Cyclone) over
# the loopback configuration: `listen` must print exactly the JSON lines `publish` sent, one per
# ROS 2 type (order may differ). The same check, with dyad's Fast DDS side on one end, is the
# wire check proper.
#   wire_loopback_test.sh WIRE_PEER WORK_DIR
set -euo pipefail
peer=$1
work=$2
rm -rf "$work"
mkdir -p "$work"
cd "$work"
source "$(dirname "$0")/../support/dds_domain.sh"
claim_test_domains 1 domain  # apart from concurrent tests' participants
types=13                    # the types dyad_ros2_wire_peer carries (see wire_peer.c)

"$peer" listen --count $types --timeout-s 8 --domain $domain > listen.out 2> listen.err &
listener=$!
trap 'kill $listener 2> /dev/null || true' EXIT
for _ in $(seq 100); do
  grep -qx ready listen.out && break
  sleep 0.05
done
grep -qx ready listen.out || { echo "listener not ready"; cat listen.err; exit 1; }

if ! "$peer" publish --domain $domain --wait-readers-s 8 > publish.out 2> publish.err; then
  echo "publish failed:"; cat publish.err; exit 1
fi
if ! wait $listener; then
  echo "listen failed:"; cat listen.err; exit 1
fi
trap - EXIT

grep -v -x ready listen.out | sort > heard.txt
sort publish.out > sent.txt
if [ "$(wc -l < sent.txt)" -ne $types ]; then
  echo "publish printed $(wc -l < sent.txt) lines, expected $types"; exit 1
fi
if ! diff sent.txt heard.txt; then
  echo "the listener heard other samples than were sent (< sent, > heard)"; exit 1
fi
echo "ok: $types samples, Cyclone to Cyclone, identical"
