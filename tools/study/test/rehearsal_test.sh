#!/usr/bin/env bash
# `dyad study rehearse` on the demo (models trained briefly here): 3 synthetic participants x 2
# conditions x 2 trials, stepped, from one command; the per-condition means of the summary are
# recomputed here from trials.csv (each participant's trials averaged, then the participants);
# a 20% self-report error shows in the events and in the confusion against the self-reports;
# a second rehearse runs nothing and gives the same table.
#   rehearsal_test.sh REPO BUILD_DIR WORK_DIR
set -euo pipefail
repo=$1 build=$2 work=$3
source "$(dirname "$0")/../../../tests/support/web_test.sh"
dyad=$build/bin/dyad
fresh_dir "$work"
bash "$repo/tools/sweep/test/demo_models.sh" "$repo" "$dyad" "$work"
cat > graph.yaml <<YAML
extends: $repo/configs/demo.yaml
components:
  human: {params: {dataset: $work/data}}
  mind: {params: {model: $work/demo.dpvrnn}}
  observer: {params: {model: $work/demo.dobs}}
YAML
cat > s.yaml <<YAML
study: rehearsal_test
graph: graph.yaml
data: data-study
participants: [S01, S02, S03]
conditions:
  assist: {mixer.gain: 0.3}
  follow: {mixer.gain: 0.9}
trials: 2
duration: 60
blind: true
rehearsal:
  set: {human.self_report_error: 0.2}
YAML
"$dyad" study rehearse s.yaml > rehearse.log 2>&1 || { cat rehearse.log; fail "dyad study rehearse"; }
grep -q "12 trials run, 0 failed" rehearse.log || { cat rehearse.log; fail "not 12 trials run"; }
out=data-study/rehearsal/analysis
[ "$(tail -n +2 $out/trials.csv | wc -l)" = 12 ] || fail "trials.csv: $(cat $out/trials.csv)"
[ ! -e data-study/S01/session.log ] || fail "the rehearsal wrote into the participants' folder"
# A blind study's rehearsal names no condition (the experimenter reads it before the study).
! grep -qE "(^|[,| ])(assist|follow)([,| ]|$)" $out/trials.csv $out/summary.csv $out/events.csv $out/report.md ||
  fail "the blind rehearsal named a condition: $(grep -E "(^|[,| ])(assist|follow)([,| ]|$)" $out/*.csv $out/report.md | head -3)"
# Per condition and measure, the mean over participants of each participant's mean over trials.
for measure in mean_congruence robot_follows; do
  awk -F, -v m="$measure" '
    FNR == 1 { for (i = 1; i <= NF; ++i) col[$i] = i; next }
    FILENAME ~ /trials/ && $col[m] != "" { sum[$2 "," $1] += $col[m]; n[$2 "," $1]++ }
    FILENAME ~ /summary/ && $col["measure"] == m { want[$1] = $col["mean"]; parts[$1] = $col["participants"] }
    END {
      for (k in sum) { split(k, cp, ","); pm[cp[1]] += sum[k] / n[k]; np[cp[1]]++ }
      for (c in want) {
        if (np[c] != parts[c] || np[c] != 3) { print c ": " np[c] " participants, summary says " parts[c]; bad = 1 }
        d = pm[c] / np[c] - want[c]; if (d < 0) d = -d
        if (d > 1e-5 * (1 + (want[c] < 0 ? -want[c] : want[c]))) { print c ": by hand " pm[c] / np[c] ", summary " want[c]; bad = 1 }
      }
      exit bad
    }' $out/trials.csv $out/summary.csv || fail "summary.csv is not the mean of the participants' means ($measure)"
done
# The synthetic humans said another primitive than the one they drew about 20% of the time.
read -r events wrong < <(awk -F, 'NR == 1 { for (i = 1; i <= NF; ++i) col[$i] = i; next }
  $col["self_report"] != "" { n++; if ($col["self_report"] != $col["primitive"]) w++ } END { print n + 0, w + 0 }' $out/events.csv)
[ "$events" -ge 20 ] || fail "only $events events with a self-report"
awk -v n="$events" -v w="$wrong" 'BEGIN { exit !(w >= 1 && w / n <= 0.45) }' || fail "$wrong of $events self-reports wrong (20% asked)"
off=$(awk -F, 'NR > 1 && $1 != $2 { s += $3 } END { print s + 0 }' $out/reports_vs_plan.csv)
[ "$off" = "$wrong" ] || fail "reports_vs_plan.csv has $off events off its diagonal, events.csv $wrong wrong reports"
grep -q "$wrong of $events self-reports name another primitive" $out/report.md || fail "the report does not say $wrong of $events"
off=$(awk -F, 'NR > 1 && $1 != $2 { s += $3 } END { print s + 0 }' $out/reported_confusion.csv)
[ "$off" -gt 0 ] || fail "the confusion against the self-reports has nothing off its diagonal"
if /usr/bin/python3 -c "import matplotlib" 2> /dev/null; then
  for m in mean_congruence robot_follows; do
    [ "$(head -c 8 $out/plots/$m.png | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] || fail "no plot of $m per condition"
  done
fi
cp $out/summary.csv summary.first
"$dyad" study rehearse s.yaml > again.log 2>&1 || { cat again.log; fail "the second rehearse"; }
grep -q "0 trials run, 0 failed" again.log || { cat again.log; fail "the second rehearse ran trials again"; }
cmp summary.first $out/summary.csv || fail "the same recordings gave another table"
# A rehearsal's recording put where a participant's trial belongs is refused by name.
first=$(ls data-study/rehearsal/S01/01-*.mcap | head -1)
mkdir -p data-study/S01 && cp "$first" data-study/S01/
"$dyad" study analyze s.yaml > analyze.log 2>&1 || { cat analyze.log; fail "dyad study analyze"; }
grep -q "0 trials analysed, 12 missing" analyze.log || { cat analyze.log; fail "the participants' analysis took rehearsal files"; }
grep -q "a rehearsal's recording (synthetic participant)" analyze.log || { cat analyze.log; fail "the rehearsal's file was not named"; }
echo "PASS: 12 rehearsal trials; $wrong of $events self-reports wrong; summary = the participants' means"
