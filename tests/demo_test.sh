#!/usr/bin/env bash
# The README's demo, shortened (300 steps, 200 training epochs), run twice from an empty work
# folder: the first run must produce a complete recording and report, the second must reuse the
# cached data set, model and observer. With `macaw`, the MacawBot variant (skipped, exit 77,
# when ../shared/data/vcbot is missing).
# usage: demo_test.sh REPO WORK_DIR [demo|macaw] [BUILD_DIR (default REPO/build)]
set -euo pipefail
repo=$1 work=$2 name=${3:-demo} build=${4:-$1/build}
if [ "$name" = macaw ] && [ ! -d "$repo/../shared/data/vcbot/model/MacawBot" ]; then
  echo "SKIP: the macaw demo needs ../shared/data/vcbot beside the repository (not found)"
  exit 77
fi
rm -rf "$work"
run() { DEMO_BUILD="$build" DEMO_SKIP_SETUP=1 DEMO_STEPS=300 DEMO_EPOCHS=200 DEMO_WORK="$work" bash "$repo/tools/demo.sh" "$name"; }
fail() { echo "FAIL: $*" >&2; exit 1; }

first=$(run 2>&1) || { echo "$first"; fail "first run exited non-zero"; }
rec="$work/$name/$name.mcap"
[ -f "$rec" ] || fail "no recording at $rec"
info=$("$build/bin/dyad" bag info "$rec")
echo "$info" | grep -q "state:       complete" || fail "recording not complete: $info"
for topic in human/input robot/intention robot/command robot/state observer/labels; do
  echo "$info" | grep -Eq "^  [0-9]+  $topic  300 msgs" || fail "$topic does not have 300 messages: $info"
done
report="$work/$name/report"
grep -q "^- steps: 300 of 100.0 ms" "$report/report.md" || fail "report.md: $(head -20 "$report/report.md")"
# One process, nothing lost: the report says so (a partition would be listed here, writer by writer).
grep -q "^  none: every writer's samples are contiguous to the end" "$report/report.md" ||
  fail "report.md has no transport section: $(head -30 "$report/report.md")"
# 300 steps hold the first of the 8 planned events; the other 7 are after the end and not scored.
[ "$(grep -c '^| [0-9]' "$report/report.md")" -eq 1 ] || fail "report.md should score exactly the 1 event in 300 steps"
grep -q "^- 7 planned events after the end of the recording (not scored)" "$report/report.md" ||
  fail "report.md does not say that 7 planned events were not recorded"
for png in workspace nelbo congruence; do
  [ "$(head -c 8 "$report/$png.png" | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] || fail "$png.png is not a PNG"
done
echo "$first" | grep -q "wall time (stepped clock)" || fail "no wall time line"

second=$(run 2>&1) || { echo "$second"; fail "second run exited non-zero"; }
cached=$(echo "$second" | grep -c "is up to date (cached)" || true)
expected=3
[ "$name" = macaw ] && expected=2
[ "$cached" -eq "$expected" ] || { echo "$second"; fail "second run reused $cached of $expected cached steps"; }
# A quick try of the graph by hand (no recorder.file) never replaces the demo's recording: the
# graph's own recorder file is a new {time}-named one, in the folder of the run.
# (The README's demo writes out/demo/demo.mcap of the repository; the quick try runs there too.)
if [ "$name" = demo ]; then
  mkdir -p "$work/out/demo"
  cp "$rec" "$work/out/demo/demo.mcap"
  rec="$work/out/demo/demo.mcap"
  before=$(sha256sum "$rec" | cut -d' ' -f1)
  (cd "$work" && "$build/bin/dyad" run "$repo/configs/demo.yaml" --steps 10 --quiet \
     --set "human.dataset=$work/data/analytic" --set "mind.model=$work/models/demo.dpvrnn" \
     --set "observer.model=$work/models/demo.dobs") > /dev/null 2>&1 || fail "a quick run of configs/demo.yaml failed"
  [ "$(sha256sum "$rec" | cut -d' ' -f1)" = "$before" ] || fail "a quick run replaced the demo's recording"
fi
echo "PASS: $name demo (300 steps) recorded, reported, and cached on the second run"
