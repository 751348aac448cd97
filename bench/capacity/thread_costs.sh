#!/usr/bin/env bash
# Where one process's CPU and wake-ups go, per thread (#45 item 4: what a participant costs):
#   bash bench/capacity/thread_costs.sh PID [SECONDS]
# Reads /proc/PID/task/*/{stat,status} twice, SECONDS apart (default 30), and prints per thread
# its id, name, CPU (% of a core, from utime+stime in clock ticks: 10 ms resolution, so use 20 s
# or more) and voluntary context switches per second (each one a wake-up), busiest first.
# Threads that start or end within the window are left out. Not in CI.
# E.g. beside `CAPACITY_NS=1 CAPACITY_SECONDS=200 bash bench/capacity/bench_capacity.sh`:
#   bash bench/capacity/thread_costs.sh "$(pgrep -f 'dyad run .*interactive' | head -1)" 40
set -euo pipefail
pid=${1:?usage: thread_costs.sh PID [SECONDS]}
seconds=${2:-30}
[[ $pid =~ ^[0-9]+$ ]] && [ -d "/proc/$pid" ] || { echo "thread_costs: no process $pid" >&2; exit 2; }
[[ $seconds =~ ^[1-9][0-9]*$ ]] || { echo "thread_costs: SECONDS: '$seconds' is not a whole number > 0" >&2; exit 2; }
ticks=$(getconf CLK_TCK)
snap() {  # tid name cpu_ticks voluntary_switches, sorted by tid (as join wants)
  for t in /proc/"$pid"/task/*; do
    local stat fields
    stat=$(cat "$t/stat" 2> /dev/null) || continue  # ended meanwhile
    read -r -a fields <<< "${stat##*) }"              # the fields after "(name)": state is [0]
    echo "${t##*/} $(tr ' ' '_' < "$t/comm") $((fields[11] + fields[12])) $(awk '/^voluntary_ctxt_switches/ {print $2}' "$t/status")"
  done | sort -k1,1
}
before=$(snap); sleep "$seconds"; after=$(snap)
[ -n "$after" ] || { echo "thread_costs: process $pid ended during the window" >&2; exit 1; }
echo "tid name cpu_%_of_a_core wakeups_per_s"
join <(echo "$before") <(echo "$after") |
  awk -v s="$seconds" -v hz="$ticks" '{printf "%s %s %.2f %.0f\n", $1, $2, 100 * ($6 - $3) / hz / s, ($7 - $4) / s}' |
  sort -k3,3gr -k4,4gr
