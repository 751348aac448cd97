#!/usr/bin/env bash
# nrl_reference.sh: reference traces of the original library's (NRL) online error regression on
# the study's trained model (MacawBot), for issue #44 (dyad's NRL mode is checked against them).
#
#   bench/pvrnn/nrl_reference.sh NRL_SOURCE_DIR [OUT_DIR]
#
# NRL_SOURCE_DIR: a checkout of github.com/oist-cnru/NRL (not part of this repository; the traces
# in components/pvrnn/test/data/nrl/ were made from commit 42395a2, its newest). The script copies
# its src/ to a temporary folder, builds NRL's shared library with NRL's own CMake (src/lib) and
# bench/pvrnn/nrl_er_harness.cpp against it, and runs the harness (see its header) on the
# switching workload with dyad's vcbot ER settings (W 5, 15 Adam iterations, lr 0.3, beta1 0.1,
# beta2 0.95, meta-prior 1e-5 per layer):
#   OUT_DIR/nrl_er_fixed.csv   fixed executed trajectory (the same input for every engine)
#   OUT_DIR/nrl_er_closed.csv  closed loop (the executed positions follow NRL's intentions)
#   OUT_DIR/nrl_train.csv      NRL's training from its initial state (bench/pvrnn/nrl_train_harness.cpp:
#                              the study's properties_MacawBot.d on the Macaw data set), loss terms
#                              per epoch for NRL_TRAIN_EPOCHS epochs
# OUT_DIR defaults to components/pvrnn/test/data/nrl.
#
# Environment:
#   NRL_FLAGS  compiler flags of the reference build (default "-O3 -DNDEBUG")
#   NRL_NOISE  0 (default): NRL's N(0,1) draws (Utils::randN) replaced by 0 in the copy, so a
#              trace does not depend on libstdc++'s normal_distribution; 1: NRL as published
#              (std::default_random_engine seeded 0)
#   NRL_REPRO  1: also measure NRL's reproducibility: build it with its CMake defaults (no flags)
#              and with -O3 -march=native, run the fixed trajectory with both, print the first
#              step where the intentions differ by more than 5e-5 (and at 1e-3, 1e-1); train
#              with both and print, per pair of the three builds, the first epoch where a loss
#              term differs by more than 1e-5, 1e-4, 1e-3 relative and the largest difference
#              through NRL_TRAIN_HORIZON (default 52)
#   NRL_TRAIN_EPOCHS  epochs of the training trace (default 200)
#   NRL_ENSEMBLE  N > 0: also run the closed loop N times with 1e-5 jitter on the executed
#              positions (seeds 1..N, reference build) and print switching figures per run
#              (bench/pvrnn/nrl_switch_figures.py; needs python3)
#   NRL_WORK   a folder to build in and keep (default: a temporary one, removed); a build whose
#              library exists there is reused
# Needs cmake, a C++ compiler and Eigen (/usr/include/eigen3 or EIGEN3_INCLUDE_DIR).
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
nrl_src="$(cd "${1:?usage: nrl_reference.sh NRL_SOURCE_DIR [OUT_DIR]}" && pwd)"
out="${2:-$repo/components/pvrnn/test/data/nrl}"
data="$repo/../shared/data/vcbot"
eigen="${EIGEN3_INCLUDE_DIR:-/usr/include/eigen3}"
flags="${NRL_FLAGS:--O3 -DNDEBUG}"
noise="${NRL_NOISE:-0}"

[[ -f "$nrl_src/src/lib/LibNRL.h" ]] || { echo "error: $nrl_src: not an NRL checkout (no src/lib/LibNRL.h)" >&2; exit 2; }
[[ -d "$data/model/MacawBot" ]] || { echo "error: $data/model/MacawBot: the study's trained model is missing" >&2; exit 2; }
[[ "$noise" == 0 || "$noise" == 1 ]] || { echo "error: NRL_NOISE must be 0 or 1, got '$noise'" >&2; exit 2; }
train_epochs="${NRL_TRAIN_EPOCHS:-200}"
[[ "$train_epochs" =~ ^[1-9][0-9]*$ ]] || { echo "error: NRL_TRAIN_EPOCHS must be a count > 0, got '$train_epochs'" >&2; exit 2; }
train_horizon="${NRL_TRAIN_HORIZON:-52}"
[[ "$train_horizon" =~ ^[1-9][0-9]*$ ]] || { echo "error: NRL_TRAIN_HORIZON must be a count > 0, got '$train_horizon'" >&2; exit 2; }
ensemble="${NRL_ENSEMBLE:-0}"
[[ "$ensemble" =~ ^[0-9]+$ ]] || { echo "error: NRL_ENSEMBLE must be a count, got '$ensemble'" >&2; exit 2; }
mkdir -p "$out"
out="$(cd "$out" && pwd)"

if [[ -n "${NRL_WORK:-}" ]]; then  # kept (builds reused when present), for iterating
  work="$NRL_WORK"; mkdir -p "$work"
else
  work="$(mktemp -d)"; trap 'rm -rf "$work"' EXIT
fi
rm -rf "$work/src" && cp -r "$nrl_src/src" "$work/src"
if [[ "$noise" == 0 ]]; then
  # Utils::randN (src/utils/Utils.h) fills its argument with distribution(generator).
  grep -q '\*d = distribution(generator);' "$work/src/utils/Utils.h" ||
    { echo "error: $nrl_src/src/utils/Utils.h: randN not as expected, cannot set the noise to 0" >&2; exit 1; }
  sed -i 's/\*d = distribution(generator);/*d = 0.0f;/' "$work/src/utils/Utils.h"
fi

# build NAME FLAGS: NRL's library (its CMake, src/lib) and the harness, both with FLAGS.
build() {
  local name="$1" cflags="$2" b="$work/build-$1"
  echo "building NRL ($name: '${cflags:-NRL CMake defaults}') ..."
  if [[ ! -f "$b/libNRL.so" ]]; then
  cmake -S "$work/src/lib" -B "$b" -DCMAKE_CXX_FLAGS="$cflags -isystem $eigen -w" >"$work/$name.log" 2>&1 ||
    { cat "$work/$name.log" >&2; exit 1; }
  cmake --build "$b" -j1 >>"$work/$name.log" 2>&1 || { tail -30 "$work/$name.log" >&2; exit 1; }
  fi
  ${CXX:-c++} -std=c++17 $cflags -Wall -Wextra -isystem "$eigen" -isystem "$work/src" \
    "$here/nrl_er_harness.cpp" -o "$b/nrl_er_harness" -L"$b" -lNRL -Wl,-rpath,"$b" 2>>"$work/$name.log" ||
    { tail -30 "$work/$name.log" >&2; exit 1; }
  ${CXX:-c++} -std=c++17 $cflags -Wall -Wextra -isystem "$eigen" -isystem "$work/src" \
    "$here/nrl_train_harness.cpp" -o "$b/nrl_train_harness" -L"$b" -lNRL -Wl,-rpath,"$b" 2>>"$work/$name.log" ||
    { tail -30 "$work/$name.log" >&2; exit 1; }
}

# train NAME CSV [harness options]: NRL's training from its initial state (a fresh process: NRL's
# initial weights come from rand() in its default state), the study's properties file.
train() {
  local name="$1" csv="$2"
  shift 2
  local r="$work/train-$name"
  mkdir -p "$r"
  ln -sfn "$(cd "$data/dataset/Macaw" && pwd)" "$r/Macaw"
  sed 's/^modelpath=.*/modelpath=unused/' "$data/config/properties_MacawBot.d" >"$r/props.d"
  (cd "$r" && "$work/build-$name/nrl_train_harness" props.d "$csv" --epochs "$train_epochs" "$@") >"$r/log" 2>&1 ||
    { cat "$r/log" >&2; exit 1; }
}

# run NAME CSV [harness options]: NRL reads modelpath/datapath relative to the working directory.
run() {
  local name="$1" csv="$2"
  shift 2
  local r="$work/run-$name"
  mkdir -p "$r"
  ln -sfn "$(cd "$data/model/MacawBot" && pwd)" "$r/MacawBot"
  ln -sfn "$(cd "$data/dataset/Macaw" && pwd)" "$r/Macaw"
  cp "$data/config/properties_MacawBot.d" "$r/props.d"
  (cd "$r" && "$work/build-$name/nrl_er_harness" props.d "$csv" --data Macaw "$@") >"$r/log" 2>&1 ||
    { cat "$r/log" >&2; exit 1; }
}

build ref "$flags"
run ref "$out/nrl_er_fixed.csv"
run ref "$out/nrl_er_closed.csv" --closed-loop
train ref "$out/nrl_train.csv"
echo "wrote $out/nrl_er_fixed.csv, $out/nrl_er_closed.csv and $out/nrl_train.csv (NRL $(git -C "$nrl_src" rev-parse --short HEAD 2>/dev/null || echo '?'), flags '$flags', noise $noise)"

if [[ "${NRL_REPRO:-0}" == 1 ]]; then
  build default ""
  build native "-O3 -march=native -DNDEBUG"
  run default "$work/default.csv"
  run native "$work/native.csv"
  # First step (column 1) where |intention| (columns 4, 5) of the two builds differ by > tol.
  paste -d, "$work/default.csv" "$work/native.csv" | awk -F, -v n="$(head -1 "$work/default.csv" | awk -F, '{print NF}')" '
    NR > 1 {
      d = $4 - $(n + 4); if (d < 0) d = -d; e = $5 - $(n + 5); if (e < 0) e = -e; if (e > d) d = e
      split("5e-5 1e-3 1e-1", tols, " ")
      for (k = 1; k <= 3; k++) if (!(k in first) && d > tols[k] + 0) first[k] = $1
      if (d > max) max = d
    }
    END {
      for (k = 1; k <= 3; k++) printf "NRL default vs -O3 -march=native: intentions first differ by > %s at step %s (lead-in steps negative)\n", tols[k], (k in first ? first[k] : "never")
      printf "largest difference over the run: %g\n", max
    }'
  train default "$work/train-default.csv"
  train native "$work/train-native.csv"
  # Per pair of builds: the first epoch where loss, reconstruction or regulation (columns 2-4)
  # differ by more than tol relative, and the largest difference through the horizon.
  paste -d, "$out/nrl_train.csv" "$work/train-default.csv" "$work/train-native.csv" | awk -F, -v h="$train_horizon" '
    NR > 1 {
      for (k = 0; k < 3; k++) {
        a = $(2 + k); b = $(6 + k); c = $(10 + k)
        r[1] = (a - b) / a; r[2] = (a - c) / a; r[3] = (b - c) / b
        for (j = 1; j <= 3; j++) {
          x = r[j] < 0 ? -r[j] : r[j]
          for (t = 1; t <= 3; t++) if (!((j, t) in first) && x > 10 ^ (-6 + t)) first[j, t] = $1
          if ($1 <= h && x > worst[j, k]) worst[j, k] = x
        }
      }
    }
    END {
      split("-O3/defaults -O3/-O3-march=native defaults/-O3-march=native", name, " ")
      for (j = 1; j <= 3; j++)
        printf "NRL training %s: a loss term first differs by > 1e-5 at epoch %s, > 1e-4 at %s, > 1e-3 at %s; largest through epoch %d: loss %g, reconstruction %g, regulation %g\n",
          name[j], first[j, 1], first[j, 2], first[j, 3], h, worst[j, 0], worst[j, 1], worst[j, 2]
    }'
fi

for ((s = 1; s <= ensemble; s++)); do
  run ref "$work/ens-$s.csv" --closed-loop --jitter 1e-5 --seed "$s"
  echo "seed $s: $(python3 "$here/nrl_switch_figures.py" "$work/ens-$s.csv" "$data/dataset/Macaw")"
done
