#!/usr/bin/env bash
# bench_nrl_ratio.sh: training speed of dyad against the original library (NRL) on the study's
# data set and settings (Macaw, MacawBot), measured in one run, as a ratio.
#
#   bench/pvrnn/bench_nrl_ratio.sh NRL_SOURCE_DIR [EPOCHS] [BENCH_BINARY]
#
# NRL_SOURCE_DIR: a checkout of github.com/oist-cnru/NRL (not part of this repository). It is
# built -O3 -march=native in a temporary folder (its stand-alone program NRL_SA), trained for
# EPOCHS epochs (default 500, a multiple of 100: NRL reports its time per 100 epochs) from
# scratch, then bench_pvrnn_train runs the same number of epochs. Prints both ms/epoch and
# NRL / dyad. BENCH_BINARY defaults to build/bin/bench_pvrnn_train of this checkout.
# Needs cmake, a C++ compiler and Eigen (/usr/include/eigen3 or EIGEN3_INCLUDE_DIR).
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
nrl_src="$(cd "${1:?usage: bench_nrl_ratio.sh NRL_SOURCE_DIR [EPOCHS] [BENCH_BINARY]}" && pwd)"
epochs="${2:-500}"
bench="${3:-$repo/build/bin/bench_pvrnn_train}"
data="$repo/../shared/data/vcbot"
eigen="${EIGEN3_INCLUDE_DIR:-/usr/include/eigen3}"

[[ -f "$nrl_src/src/standalone/CMakeLists.txt" ]] || { echo "error: $nrl_src: not an NRL checkout (no src/standalone)" >&2; exit 2; }
[[ -d "$data/dataset/Macaw" ]] || { echo "error: $data/dataset/Macaw: the study's data set is missing" >&2; exit 2; }
[[ -x "$bench" ]] || { echo "error: $bench: build bench_pvrnn_train first" >&2; exit 2; }
(( epochs >= 100 && epochs % 100 == 0 )) || { echo "error: EPOCHS must be a multiple of 100, got $epochs" >&2; exit 2; }

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
echo "building NRL from $nrl_src in $work ..."
cmake -S "$nrl_src/src/standalone" -B "$work/build" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_CXX_FLAGS="-O3 -march=native -DNDEBUG -isystem $eigen -w" >"$work/cmake.log" 2>&1 ||
  { cat "$work/cmake.log" >&2; exit 1; }
cmake --build "$work/build" -j"$(nproc)" >"$work/build.log" 2>&1 || { tail -30 "$work/build.log" >&2; exit 1; }

# NRL reads datapath/modelpath relative to the working directory.
mkdir -p "$work/run/MacawBot"
ln -s "$(cd "$data/dataset/Macaw" && pwd)" "$work/run/Macaw"
sed "s/^epochs=.*/epochs=$epochs/" "$data/config/properties_MacawBot.d" >"$work/run/props.d"
echo "training NRL for $epochs epochs ..."
(cd "$work/run" && "$work/build/NRL_SA" "$work/run/props.d" train) >"$work/nrl.log" 2>&1
# "Epoch [100] - Time [679.4ms] - ...": the time of the last 100 epochs.
nrl_ms=$(sed -n 's/^Epoch \[[0-9]*\] - Time \[\([0-9.]*\)ms\].*/\1/p' "$work/nrl.log" |
  awk -v e="$epochs" '{s += $1} END {if (NR * 100 != e) exit 1; printf "%.4f", s / e}') ||
  { echo "error: NRL did not report $epochs epochs; its log:" >&2; tail -20 "$work/nrl.log" >&2; exit 1; }

echo "training dyad for $epochs epochs ..."
"$bench" --epochs "$epochs" | tee "$work/dyad.log" | sed -n '1,2p'
# The float rows: 1 chunk on 1 thread, 2 chunks on 1 thread, 2 chunks on 2 threads (the default).
dyad_1=$(awk '$1 == "float" && $2 == 1 && $3 == 1 {print $4}' "$work/dyad.log")
dyad_2=$(awk '$1 == "float" && $2 == 2 && $3 == 2 {print $4}' "$work/dyad.log")

printf '%-34s %10s %10s\n' "" "ms/epoch" "NRL / it"
printf '%-34s %10.3f %10s\n' "NRL (float, one sequence at a time)" "$nrl_ms" "1.0"
ratio() { awk -v a="$1" -v b="$2" 'BEGIN {printf "%.1f", a / b}'; }
printf '%-34s %10.3f %9sx\n' "dyad float, 1 thread, 1 chunk" "$dyad_1" "$(ratio "$nrl_ms" "$dyad_1")"
printf '%-34s %10.3f %9sx\n' "dyad float, 2 threads, 2 chunks" "$dyad_2" "$(ratio "$nrl_ms" "$dyad_2")"
