#!/usr/bin/env bash
# `dyad sweep` over the demo (the PV-RNN mind, the mixer, the observer; models trained briefly
# here): the same sweep with one worker, with two, and killed part-way then resumed gives the
# same sweep.csv byte for byte (stepped runs are deterministic and never see each other on DDS,
# whatever runs beside them), with real metrics in it, and plots.
#   demo_sweep_test.sh REPO BUILD_DIR WORK_DIR
set -euo pipefail
repo=$1 build=$2 work=$3
dyad=$build/bin/dyad
fail() { echo "FAIL: $*" >&2; exit 1; }
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work"; mkdir -p "$work"; cd "$work"
bash "$here/demo_models.sh" "$repo" "$dyad" "$work"
cat > s.yaml <<YAML
sweep: demo_test
graph: $repo/configs/demo.yaml
duration: 60
set: {human.dataset: $work/data, mind.model: $work/demo.dpvrnn, observer.model: $work/demo.dobs}
grid:
  mixer.gain: [0.3, 0.9]
seeds: [1, 2, 3]
YAML
"$dyad" sweep s.yaml -o one -j 1 > one.log || { cat one.log; fail "sweep -j 1"; }
"$dyad" sweep s.yaml -o two -j 2 > two.log || { cat two.log; fail "sweep -j 2"; }
cmp one/sweep.csv two/sweep.csv || fail "one worker and two give different tables: $(diff one/sweep.csv two/sweep.csv)"
# Killed (the sweep and its runs, as Ctrl-C or a lost session would) once a run has finished.
setsid "$dyad" sweep s.yaml -o killed -j 1 --no-plots > killed.log 2>&1 &
pid=$!
for _ in $(seq 600); do [ -n "$(ls killed/runs/*/metrics.json 2> /dev/null)" ] && break; sleep 0.02; done
kill -KILL -- -"$pid" 2> /dev/null || true
wait "$pid" 2> /dev/null || true
done_before=$(ls killed/runs/*/metrics.json 2> /dev/null | wc -l)
{ [ "$done_before" -ge 1 ] && [ "$done_before" -lt 6 ]; } || fail "killed after $done_before of 6 runs (want part-way)"
"$dyad" sweep s.yaml -o killed -j 2 > resumed.log || { cat resumed.log; fail "resumed sweep"; }
grep -q "$((6 - done_before)) ran, $done_before done before, 0 failed" resumed.log || { cat resumed.log; fail "the resume did not skip the finished runs"; }
cmp one/sweep.csv killed/sweep.csv || fail "the resumed sweep's table differs: $(diff one/sweep.csv killed/sweep.csv)"
# Real numbers: every run scored events, and the gain changed what the robot did.
awk -F, 'NR > 1 && ($2 != "ok" || $7 < 1 || $8 == "") { bad = 1 } END { exit bad }' one/sweep.csv ||
  fail "a run without scored events or congruence: $(cat one/sweep.csv)"
[ "$(awk -F, 'NR > 1 { print $8 }' one/sweep.csv | sort -u | wc -l)" -gt 1 ] || fail "every run has the same congruence"
if /usr/bin/python3 -c "import matplotlib" 2> /dev/null; then
  [ "$(head -c 8 one/plots/mean_congruence__mixer.gain.png | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] ||
    fail "no plot of mean_congruence against mixer.gain"
fi
echo "PASS: 6 runs, one worker = two workers = killed after $done_before and resumed; $(head -1 one/sweep.csv)"
