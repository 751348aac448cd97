#!/usr/bin/env bash
# Installs this build of dyad into a prefix, builds tests/out_of_tree/plugin as a separate CMake
# project against it, and runs a graph that uses the plugin with the installed `dyad`.
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
domain=$(( 1 + $$ % 200 ))
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
