#!/usr/bin/env bash
# bench_demo_training.sh: the demo's training (configs/train/demo.yaml: tools/demo.sh's step 2)
# with this checkout's engine and with the engine before issue #24's speed-up (commit d616e50),
# measured in one run, alternating, as ms/epoch and a ratio.
#
#   bash bench/pvrnn/bench_demo_training.sh [EPOCHS] [ROUNDS]
#
# Builds the old `dyad` once into build/bench-old (a git worktree of d616e50 under
# build/bench-old/src; kept for the next run), generates the demo's data set with this checkout's
# `dyad` (build/bin/dyad, built first), then trains EPOCHS epochs (default 3000) from scratch with
# each engine ROUNDS times (default 2), old and new alternating. Rows: the demo's settings (float),
# the same in double (MacawBot's bench is double), and the new engine on one thread. The old
# engine has one thread. Prints the median ms/epoch of each row and old / new. DYAD_OLD=PATH uses
# an old `dyad` built elsewhere instead.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
epochs="${1:-3000}"
rounds="${2:-2}"
old_commit=d616e50
new="$repo/build/bin/dyad"
old_dir="$repo/build/bench-old"
old="${DYAD_OLD:-$old_dir/build/bin/dyad}"  # DYAD_OLD: an old dyad built elsewhere

[[ -x "$new" ]] || { echo "error: $new: build this checkout first (bash tools/build.sh)" >&2; exit 2; }
[[ "$epochs" =~ ^[0-9]+$ && "$epochs" -ge 100 ]] || { echo "error: EPOCHS must be a number >= 100, got $epochs" >&2; exit 2; }
[[ "$rounds" =~ ^[0-9]+$ && "$rounds" -ge 1 ]] || { echo "error: ROUNDS must be a number >= 1, got $rounds" >&2; exit 2; }

if [[ ! -x "$old" ]]; then
  echo "building the engine before #24 ($old_commit) in $old_dir (once; about 10 minutes on 2 cores) ..."
  mkdir -p "$old_dir"
  [[ -d "$old_dir/src" ]] || git -C "$repo" worktree add --detach "$old_dir/src" "$old_commit" >/dev/null
  cmake -S "$old_dir/src" -B "$old_dir/build" -DCMAKE_BUILD_TYPE=Release -DDYAD_BUILD_TESTS=OFF -DDYAD_BUILD_BENCH=OFF \
    >"$old_dir/configure.log" 2>&1 || { tail -20 "$old_dir/configure.log" >&2; exit 1; }
  cmake --build "$old_dir/build" --target dyad -j2 >"$old_dir/build.log" 2>&1 || { tail -30 "$old_dir/build.log" >&2; exit 1; }
fi

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
"$new" generate dataset --out "$work/data" >/dev/null
# old|new, label, extra --set: one row each.
rows=("float|the demo (float)|" "double|the demo in double|scalar=double" "float1|new engine, 1 thread (float)|threads=1")

# Seconds of one training of EPOCHS epochs (the process's wall time; the data set is read once).
train() {
  local dyad=$1 set=$2 out=$3
  local args=(train "$repo/configs/train/demo.yaml" --set "dataset=$work/data" --set "output=$out" --set "epochs=$epochs"
              --set "log_every=$epochs" --set "checkpoint_every=0")
  [[ -n "$set" ]] && args+=(--set "$set")
  local t0 t1
  t0=$(date +%s.%N)
  "$dyad" "${args[@]}" >"$work/train.log" 2>&1 || { cat "$work/train.log" >&2; exit 1; }
  t1=$(date +%s.%N)
  awk -v a="$t0" -v b="$t1" 'BEGIN { print b - a }'
}

declare -A times
for ((r = 1; r <= rounds; r++)); do
  for row in "${rows[@]}"; do
    IFS='|' read -r key label set <<<"$row"
    if [[ "$key" != float1 ]]; then
      times[old,$key]+="$(train "$old" "$set" "$work/old.dpvrnn") "
    fi
    times[new,$key]+="$(train "$new" "$set" "$work/new.dpvrnn") "
  done
  echo "round $r of $rounds done" >&2
done

median() { tr ' ' '\n' | grep -v '^$' | sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}'; }
ms_per_epoch() { awk -v s="$1" -v n="$epochs" 'BEGIN { print s * 1000 / n }'; }

printf "demo training, %s epochs, median of %s rounds (ms/epoch; process wall time / epochs)\n" "$epochs" "$rounds"
printf "%-34s %12s %12s %10s\n" "set-up" "old $old_commit" "new" "old/new"
old_float=""
for row in "${rows[@]}"; do
  IFS='|' read -r key label set <<<"$row"
  n=$(ms_per_epoch "$(echo "${times[new,$key]}" | median)")
  if [[ "$key" == float1 ]]; then
    o=$old_float
  else
    o=$(ms_per_epoch "$(echo "${times[old,$key]}" | median)")
    [[ "$key" == float ]] && old_float=$o
  fi
  printf "%-34s %12.3f %12.3f %9.2fx\n" "$label" "$o" "$n" "$(awk -v o="$o" -v n="$n" 'BEGIN { print o / n }')"
done
echo "(the 1-thread row's old column is the old engine's float time: it had one thread)"
