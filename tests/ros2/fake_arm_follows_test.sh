#!/usr/bin/env bash
# ros2.fake_arm_follows: dyad_ros2_fake_arm in pose mode (lag 0.1 s) follows target poses that
# dyad_ros2_wire_peer publishes at 50 Hz; the poses it publishes, heard by the wire peer, start
# at --initial and are within 1 mm of the target from 1 s after the arm first moved.
#   fake_arm_follows_test.sh FAKE_ARM WIRE_PEER WORK_DIR
set -euo pipefail
arm=$1
peer=$2
work=$3
rm -rf "$work"
mkdir -p "$work"
cd "$work"
source "$(dirname "$0")/../support/dds_domain.sh"
claim_test_domains 1 domain  # apart from concurrent tests' participants

pids=()
trap 'for p in "${pids[@]}"; do kill "$p" 2> /dev/null || true; done' EXIT
wait_ready() {  # FILE
  for _ in $(seq 100); do
    grep -qx ready "$1" && return 0
    sleep 0.05
  done
  echo "$1: not ready"; return 1
}

"$arm" --mode pose --lag-s 0.1 --initial 0.4,0,0.3 --domain $domain --log arm.csv > arm.out 2> arm.err &
pids+=($!)
arm_pid=$!
wait_ready arm.out
"$peer" poses --for-s 3.5 --domain $domain > poses.out 2> poses.err &
pids+=($!)
poses_pid=$!
wait_ready poses.out
sleep 0.5  # poses at the initial position before any command
"$peer" command --mode pose --to 0.5,0.1,0.2 --for-s 2.5 --domain $domain 2> command.err
wait $poses_pid || { echo "poses failed:"; cat poses.err; exit 1; }
kill -TERM $arm_pid
wait $arm_pid || { echo "the fake arm did not exit 0 on SIGTERM:"; cat arm.err; exit 1; }
trap - EXIT

python3 - poses.out <<'PY'
import json, math, sys
poses = [json.loads(l) for l in open(sys.argv[1]) if l.startswith("{")]
assert poses, "no poses"
initial, target = (0.4, 0.0, 0.3), (0.5, 0.1, 0.2)
def xyz(p): q = p["sample"]["pose"]["position"]; return (q["x"], q["y"], q["z"])
def stamp(p): s = p["sample"]["header"]["stamp"]; return s["sec"] + s["nanosec"] * 1e-9
for p in poses:
    assert p["type"] == "geometry_msgs/msg/PoseStamped"
    assert p["sample"]["header"]["frame_id"] == "base_link", p
    assert p["sample"]["pose"]["orientation"] == {"x": 0, "y": 0, "z": 0, "w": 1}, p
assert math.dist(xyz(poses[0]), initial) < 1e-9, f"first pose {xyz(poses[0])} is not the initial {initial}"
moved = next((stamp(p) for p in poses if math.dist(xyz(p), initial) > 1e-9), None)
assert moved is not None, "the arm never moved"
late = [p for p in poses if stamp(p) >= moved + 1.0]
assert len(late) > 50, f"only {len(late)} poses 1 s after the arm moved"
worst = max(math.dist(xyz(p), target) for p in late)
assert worst < 1e-3, f"error {worst} m 1 s after the arm moved"
print(f"ok: {len(poses)} poses, error <= {worst:.3g} m from 1 s after the first move")
PY
