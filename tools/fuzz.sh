#!/usr/bin/env bash
# libFuzzer targets of tests/fuzz (docs/fuzzing.md). They live in ./build-san, the ASan + UBSan
# build of tools/check.sh (one instrumented build serves both: clang 14, -DDYAD_FUZZ=ON).
#
#   bash tools/fuzz.sh list                  the targets
#   bash tools/fuzz.sh build                 install clang 14 if needed, configure, build them
#   bash tools/fuzz.sh run TARGET [SECONDS]  fuzz one target (default 600 s), one process
#   bash tools/fuzz.sh all [SECONDS]         fuzz every target in turn (default 600 s each)
#   bash tools/fuzz.sh replay [TARGET]       run every seed and regression input once (CI does)
#
# New inputs go to build-san/fuzz/corpus/TARGET, crashes to build-san/fuzz/artifacts/TARGET/.
# Limits: 2 GB RSS, no single allocation over 256 MB (-malloc_limit_mb): a reader that trusts a
# length field before checking it against the file size fails here. Extra libFuzzer flags:
# FUZZ_FLAGS="-max_len=65536" bash tools/fuzz.sh run mcap 120
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
dir=$here/build-san
targets=$(cd "$here/tests/fuzz" && ls fuzz_*.cpp | grep -v "^fuzz_support" | sed 's/^fuzz_//; s/\.cpp$//')
mode=${1:-list}

build() {
  bash "$here/tools/setup.sh" sanitize
  if [ ! -f "$dir/CMakeCache.txt" ]; then
    mkdir -p "$dir"
    cmake -S "$here" -B "$dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
      -DCMAKE_C_COMPILER=clang-14 -DCMAKE_CXX_COMPILER=clang++-14 \
      -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" \
      -DDYAD_SANITIZE=address,undefined -DDYAD_FUZZ=ON -DDYAD_BUILD_BENCH=OFF > "$dir/configure.log" 2>&1 || {
      cat "$dir/configure.log"; exit 1; }
  fi
  # shellcheck disable=SC2046
  nice -n 10 cmake --build "$dir" -j2 --target $(for t in $targets; do echo "dyad_fuzz_$t"; done)
}

export ASAN_OPTIONS="abort_on_error=1:detect_leaks=1${ASAN_OPTIONS:+:$ASAN_OPTIONS}"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1${UBSAN_OPTIONS:+:$UBSAN_OPTIONS}"
export ASAN_SYMBOLIZER_PATH=/usr/bin/llvm-symbolizer-14

run() {  # run TARGET SECONDS
  local t=$1 seconds=$2
  local bin=$dir/bin/dyad_fuzz_$t
  [ -x "$bin" ] || { echo "fuzz: no $bin (bash tools/fuzz.sh build)" >&2; exit 2; }
  mkdir -p "$dir/fuzz/corpus/$t" "$dir/fuzz/artifacts/$t"
  local args=(-max_total_time="$seconds" -rss_limit_mb=2048 -malloc_limit_mb=256 -timeout=10
    -print_final_stats=1 -artifact_prefix="$dir/fuzz/artifacts/$t/")
  case $t in
    graph | graph_chain) args+=(-dict="$here/tests/fuzz/dict/graph.dict") ;;
    cdr_schema) args+=(-dict="$here/tests/fuzz/dict/idl.dict") ;;
    model_file | observer_file) args+=(-dict="$here/tests/fuzz/dict/checked_file.dict") ;;
  esac
  local corpora=("$dir/fuzz/corpus/$t" "$dir/fuzz/seeds/$t")
  [ -d "$here/tests/fuzz/regressions/$t" ] && corpora+=("$here/tests/fuzz/regressions/$t")
  # shellcheck disable=SC2086
  nice -n 10 "$bin" "${args[@]}" ${FUZZ_FLAGS:-} "${corpora[@]}"
}

case "$mode" in
  list) echo "$targets" ;;
  build) build ;;
  run) [ $# -ge 2 ] || { echo "usage: tools/fuzz.sh run TARGET [SECONDS]" >&2; exit 2; }
       build; run "$2" "${3:-600}" ;;
  all) build; for t in $targets; do run "$t" "${2:-600}"; done ;;
  replay) build; (cd "$dir" && ctest --output-on-failure -L fuzz ${2:+-R "fuzz.replay.$2\$"}) ;;
  *) echo "usage: tools/fuzz.sh list|build|run TARGET [SECONDS]|all [SECONDS]|replay [TARGET]" >&2; exit 2 ;;
esac
