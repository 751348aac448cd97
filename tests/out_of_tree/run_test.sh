#!/usr/bin/env bash
# Installs this build of dyad into a prefix, builds tests/out_of_tree/plugin as a separate CMake
# project against it, and runs a graph that uses the plugin with the installed `dyad`. Then builds
# the installed example messages/ (a plugin with its own IDL message type, dyad_add_messages),
# records and exports its type, and echoes it from a live graph.
set -euo pipefail
build=$1
work=$2
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work"
mkdir -p "$work"
cmake --install "$build" --prefix "$work/prefix" > "$work/install.log"
cmake -S "$here/plugin" -B "$work/plugin-build" -DCMAKE_PREFIX_PATH="$work/prefix" -DCMAKE_BUILD_TYPE=Release > "$work/configure.log"
cmake --build "$work/plugin-build" -j2 > "$work/build.log"
plugin="$work/plugin-build/doubler.so"
test -f "$plugin"
source "$here/../support/dds_domain.sh"
claim_test_domains 1 domain
cat > "$work/graph.yaml" <<YAML
graph: oot
clock: stepped
domain_id: $domain
plugins: [$plugin]
components:
  src: {type: counter_source, rate_hz: 10, params: {start: 1}, outputs: {out: count}}
  double: {type: doubler, trigger: in, params: {factor: 3}, inputs: {in: count}, outputs: {out: tripled}}
  sink: {type: counter_sink, trigger: in, params: {file: $work/out.txt}, inputs: {in: tripled}}
YAML
"$work/prefix/bin/dyad" types --plugins "$plugin" | grep '^doubler' > /dev/null  # not grep -q: under pipefail its early exit SIGPIPEs dyad
"$work/prefix/bin/dyad" run "$work/graph.yaml" --steps 5 --quiet
expected=$'3 double 1 0\n6 double 2 100000000\n9 double 3 200000000\n12 double 4 300000000\n15 double 5 400000000'
actual=$(cat "$work/out.txt")
if [ "$actual" != "$expected" ]; then
  echo "unexpected output:"; echo "$actual"; exit 1
fi
echo "out-of-tree plugin loaded by the installed dyad and ran"

# A plugin with a message type of its own (dyad_add_messages), built from the installed example.
example="$work/prefix/share/dyad/examples/messages"
test -f "$example/distance.idl"
cmake -S "$example" -B "$work/messages-build" -DCMAKE_PREFIX_PATH="$work/prefix" -DCMAKE_BUILD_TYPE=Release > "$work/messages-configure.log"
cmake --build "$work/messages-build" -j2 > "$work/messages-build.log"
gauge="$work/messages-build/gauge.so"
# One Header only: dyad's (fastddsgen's copy for the included header.idl is not compiled in).
if nm -C --defined-only "$gauge" | grep -q 'dyad::msg::Header::Header()'; then
  echo "the plugin defines its own copy of dyad::msg::Header"; exit 1
fi
"$work/prefix/bin/dyad" types --messages --plugins "$gauge" | grep '^Distance ' > /dev/null
graph_text() {  # CLOCK FILE
  cat <<YAML
graph: gauge
clock: $1
domain_id: $domain
plugins: [$gauge]
components:
  src: {type: counter_source, rate_hz: 10, params: {start: 1}, outputs: {out: count}}
  gauge: {type: gauge, trigger: in, params: {scale: 0.5, near_below: 2}, inputs: {in: count}, outputs: {out: distance}}
  rec: {type: recorder, rate_hz: 1, params: {file: "$2", topics: [distance]}}
YAML
}
graph_text stepped "$work/gauge.mcap" > "$work/gauge.yaml"
"$work/prefix/bin/dyad" run "$work/gauge.yaml" --steps 5 --quiet
"$work/prefix/bin/dyad" bag export "$work/gauge.mcap" --csv "$work/csv" > /dev/null
expected='log_time,publish_time,sequence,header.source,header.sequence_number,header.stamp_ns,value,near
0.5,true
1,true
1.5,true
2,false
2.5,false'
actual=$(head -1 "$work/csv/distance.csv"; tail -n +2 "$work/csv/distance.csv" | cut -d, -f7-)
if [ "$actual" != "$expected" ]; then
  echo "unexpected export of the plugin's own type:"; echo "$actual"; exit 1
fi
# A live graph: `dyad echo` decodes the plugin's type with --graph, and says what is missing without.
graph_text wall "$work/gauge-wall-{time}.mcap" > "$work/gauge-wall.yaml"
"$work/prefix/bin/dyad" run "$work/gauge-wall.yaml" --duration 20 --quiet &
run_pid=$!
trap 'kill $run_pid 2>/dev/null || true' EXIT
echo_out=$("$work/prefix/bin/dyad" echo distance -n 2 --domain "$domain" --graph "$work/gauge-wall.yaml" --wait 10)
case "$echo_out" in
  *'"value":'*'"near":'*) ;;
  *) echo "dyad echo --graph did not decode Distance: $echo_out"; exit 1 ;;
esac
if "$work/prefix/bin/dyad" echo distance -n 1 --domain "$domain" --wait 10 > /dev/null 2> "$work/echo-unknown.err"; then
  echo "dyad echo without the plugin decoded an unknown type"; exit 1
fi
grep -q "does not know: name the plugin" "$work/echo-unknown.err" || { cat "$work/echo-unknown.err"; exit 1; }
kill $run_pid; wait $run_pid 2>/dev/null || true
trap - EXIT
echo "plugin with its own message type: recorded, exported, echoed"

# A plugin bringing ROS 2 types dyad does not ship (dyad_add_messages ... ROS2), from the
# installed example: known by their ROS 2 names, recorded and exported with their fields.
example="$work/prefix/share/dyad/examples/ros2_messages"
cmake -S "$example" -B "$work/ros2-build" -DCMAKE_PREFIX_PATH="$work/prefix" -DCMAKE_BUILD_TYPE=Release > "$work/ros2-configure.log"
cmake --build "$work/ros2-build" -j2 > "$work/ros2-build.log" || { cat "$work/ros2-build.log"; exit 1; }
sensor="$work/ros2-build/force_sensor.so"
"$work/prefix/bin/dyad" types --messages --plugins "$sensor" | grep '^geometry_msgs/msg/WrenchStamped ' > /dev/null
cat > "$work/ros2.yaml" <<YAML
graph: force
clock: stepped
domain_id: $domain
plugins: [$sensor]
topics:
  wrench: {type: geometry_msgs/msg/WrenchStamped}
components:
  src: {type: counter_source, rate_hz: 10, params: {start: 1}, outputs: {out: count}}
  sensor: {type: force_sensor, trigger: in, params: {newtons_per_count: 0.5}, inputs: {in: count}, outputs: {out: wrench}}
  rec: {type: recorder, rate_hz: 1, params: {file: "$work/ros2.mcap", topics: [wrench]}}
YAML
"$work/prefix/bin/dyad" run "$work/ros2.yaml" --steps 3 --quiet
"$work/prefix/bin/dyad" bag export "$work/ros2.mcap" --csv "$work/ros2-csv" > /dev/null
actual=$(cut -d, -f4- "$work/ros2-csv/wrench.csv")
expected='header.stamp.sec,header.stamp.nanosec,header.frame_id,wrench.force.x,wrench.force.y,wrench.force.z,wrench.torque.x,wrench.torque.y,wrench.torque.z
0,0,tool0,0.5,0,0,0,0,0
0,100000000,tool0,1,0,0,0,0,0
0,200000000,tool0,1.5,0,0,0,0,0'
if [ "$actual" != "$expected" ]; then
  echo "unexpected export of the plugin's ROS 2 type:"; echo "$actual"; exit 1
fi
echo "plugin with ROS 2 types of its own: known by their ROS 2 names, recorded, exported"
