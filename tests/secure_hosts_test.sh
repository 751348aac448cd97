#!/usr/bin/env bash
# A secured graph across machines, from the outside: network namespaces lab, mind, rec and guest
# (10.78.0.1-4/24) on a bridge in a fifth, each with a /dev/shm of its own; the graphs discover by
# static peers (network.hosts), so no multicast is needed. Modes:
#   guests     the lab's tools visiting a secured graph from `guest`, a machine that is none of its
#              hosts (issue #43 item 1). The graph: a recorder and a counter_sink of human/input on
#              lab, two writers (robot/state, robot/secret) on rec; `security.guests` lets guests
#              publish human/input and read robot/state. From guest, while it runs: `dyad echo` and
#              `dyad record` of robot/state receive; `dyad pub` and `dyad bag play` of human/input
#              reach the graph (its sink and its recording hold their values); `dyad echo` of
#              robot/secret and `dyad pub` of robot/state are refused (exit 2) naming the key of
#              the graph to change; `dyad echo` with the same graph without `security:` (an
#              unsecured tool) hears nothing. About 35 s.
#   exports    the same as guests, but each machine holds only its export (`dyad security export`:
#              lab's, rec's and the guest's, each in a folder of its own beside a copy of the
#              graph, as copied to that machine), never the whole keystore; lab's launcher is
#              started without --host (its export says which host it is); and from guest,
#              `dyad echo --host lab` is refused naming the identity host.lab and the export that
#              would give it. About 35 s.
#   starts[:N] secured against open starts under load (issue #43 item 5): N rounds (default 20) of
#              a secured three-host graph (a ring of counter_source -> counter_sink, one process
#              on each of lab, mind, rec; the three launchers started at the same instant), then
#              N of the same graph without `security:`, with a CPU hog (`yes`) per core running
#              throughout (SECURE_HOSTS_HOG=0: none). A round starts when every launcher exits 0
#              and every sink received; its time to start is from the launchers' start to the
#              last sink's first sample. In each round, once the graph runs, a tool on a graph
#              host (`dyad echo --host lab`) and one on guest (as the graph's guest when
#              secured) must each receive a sample within 10 s. Prints per round and a table:
#              starts ok / N and time to start median / max, tools ok / N and their time to the
#              first sample, secured against open. Fails unless every round of both passed.
#              For experiments: SECURE_HOSTS_KINDS="secured" (or "open") runs one kind only;
#              SECURE_HOSTS_NETWORK="lease_s: 2" adds keys to the graph's network section.
#   secure_hosts_test.sh REPO BUILD_DIR WORK_DIR [guests|exports|starts[:N]...]   (default: guests)
# Needs root and `ip netns` (skipped, exit 77, otherwise). Leaves nothing behind: the EXIT trap
# kills every process in its namespaces and deletes them.
set -euo pipefail
[ $# -ge 3 ] || { echo "usage: secure_hosts_test.sh REPO BUILD_DIR WORK_DIR [guests|exports|starts[:N]...]" >&2; exit 2; }
repo=$(cd "$1" && pwd) build=$(cd "$2" && pwd) work=$3
shift 3
modes=("$@")
[ ${#modes[@]} -gt 0 ] || modes=(guests)
for mode in "${modes[@]}"; do
  [[ $mode =~ ^(guests|exports|starts(:[0-9]+)?)$ ]] || { echo "unknown mode '$mode' (guests, exports, starts[:N])" >&2; exit 2; }
done
dyad=$build/bin/dyad
skip() { echo "SKIP: secure_hosts: $*"; exit 77; }
fail() { echo "FAIL: secure_hosts: $*" >&2; exit 1; }
[ "$(id -u)" = 0 ] || skip "needs root (it creates network namespaces)"
command -v ip > /dev/null && ip netns list > /dev/null 2>&1 || skip "no 'ip netns' (iproute2)"
[ -x "$dyad" ] || fail "no dyad at $dyad"

hosts=(lab mind rec guest)
declare -A addr
addr=([lab]=10.78.0.1 [mind]=10.78.0.2 [rec]=10.78.0.3 [guest]=10.78.0.4)
source "$repo/tests/support/netns_test.sh"
netns_names dyadsh
rm -rf "$work"
mkdir -p "$work"
work=$(cd "$work" && pwd)
cleanup() {
  local code=$?
  set +e
  trap - EXIT INT TERM
  netns_stop secure_hosts
  exit "$code"
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

netns_network
echo "secure_hosts: namespaces ${made[*]}: lab ${addr[lab]}, mind ${addr[mind]}, rec ${addr[rec]}, guest ${addr[guest]}"

# on HOST CMD...: CMD in HOST's namespace with a /dev/shm of its own, as on another machine.
on() {
  local h=$1
  shift
  ip netns exec "${ns[$h]}" sh -c 'mount -t tmpfs -o mode=1777,size=256m dyad_secure_hosts /dev/shm && exec "$@"' sh "$@"
}
now_ms() { echo $(($(date +%s%N) / 1000000)); }

# --- guests ---------------------------------------------------------------------------------------
# run_guests guests|exports (exports: each machine holds only its own export of the keystore).
run_guests() {
  local mode=$1
  local out=$work/$mode sec g lab_pid rec_pid pids=() ok=1
  mkdir -p "$out"
  for g in secured open; do
    sec=()
    [ $g = secured ] && sec=("security: {keystore: keys, guests: {publish: [human/input], subscribe: [robot/state]}}")
    printf '%s\n' "graph: visit" "clock: wall" "network: {discovery: peers, hosts: {lab: ${addr[lab]}, rec: ${addr[rec]}}}" \
      "${sec[@]}" "topics: {human/input: {type: Counter}}  # written from outside: the guests" \
      "processes:" "  arm: {host: lab}" "  ctl: {host: rec}" "components:" \
      "  sink: {type: counter_sink, trigger: in, process: arm, params: {file: $out/sink.txt}, inputs: {in: human/input}}" \
      "  rec: {type: recorder, rate_hz: 1, process: arm, params: {file: $out/visit.mcap, topics: [human/input]}}" \
      "  state: {type: counter_source, rate_hz: 20, process: ctl, outputs: {out: robot/state}}" \
      "  secret: {type: counter_source, rate_hz: 20, process: ctl, outputs: {out: robot/secret}}" > "$out/visit_$g.yaml"
  done
  # The recording `bag play` plays: 20 human/input samples counting from 7000, made offline.
  printf '%s\n' "graph: bag" "clock: stepped" "components:" \
    "  src: {type: counter_source, rate_hz: 10, params: {start: 7000}, outputs: {out: human/input}}" \
    "  rec: {type: recorder, rate_hz: 10, params: {file: $out/bag.mcap, topics: [human/input]}}" > "$out/bag.yaml"
  "$dyad" run "$out/bag.yaml" --steps 20 --quiet > "$out/bag.log" 2>&1 || { cat "$out/bag.log"; fail "guests: cannot make the recording to play"; }
  "$dyad" security init "$out/keys" --graph "$out/visit_secured.yaml" > "$out/init.log" 2>&1 ||
    { cat "$out/init.log"; fail "guests: dyad security init failed"; }
  local G=$out/visit_secured.yaml
  declare -A at=([lab]=$G [rec]=$G [guest]=$G)  # the graph file each machine uses
  if [ "$mode" = exports ]; then
    local m opt
    for m in lab rec guest; do
      opt=(--host "$m")
      [ $m = guest ] && opt=(--guest)
      mkdir -p "$out/$m"
      "$dyad" security export "$out/keys" --graph "$G" "${opt[@]}" "$out/$m/keys" > "$out/export_$m.log" 2>&1 ||
        { cat "$out/export_$m.log"; fail "exports: dyad security export ${opt[*]} failed"; }
      cp "$G" "$out/$m/visit_secured.yaml"  # keystore: keys, relative: its own export
      at[$m]=$out/$m/visit_secured.yaml
    done
  fi
  local lab_host=(--host lab)
  [ "$mode" = exports ] && lab_host=()  # lab's launcher: its export says which host it is
  on lab "$dyad" run "${at[lab]}" "${lab_host[@]}" --duration 25 --quiet > "$out/lab.log" 2>&1 &
  lab_pid=$!; started+=($!)
  on rec "$dyad" run "${at[rec]}" --host rec --duration 25 --quiet > "$out/rec.log" 2>&1 &
  rec_pid=$!; started+=($!)
  # The visitors, all on guest, while the graph starts and runs. Each waits for the graph itself.
  on guest "$dyad" echo robot/state --graph "${at[guest]}" --count 1 --wait 15 > "$out/echo.txt" 2>&1 &
  pids+=($!); started+=($!)
  on guest "$dyad" record robot/state --graph "${at[guest]}" -o "$out/guest.mcap" --duration 4 --wait 15 > "$out/record.txt" 2>&1 &
  pids+=($!); started+=($!)
  on guest "$dyad" pub human/input --graph "${at[guest]}" '{value: 4242}' --rate 5 --count 10 --wait 15 > "$out/pub.txt" 2>&1 &
  pids+=($!); started+=($!)
  on guest "$dyad" bag play "$out/bag.mcap" --graph "${at[guest]}" --wait 15 > "$out/play.txt" 2>&1 &
  pids+=($!); started+=($!)
  on guest "$dyad" echo robot/state --graph "$out/visit_open.yaml" --count 1 --wait 12 > "$out/open_echo.txt" 2>&1 &
  pids+=($!); started+=($!)
  local refused_echo=0 refused_pub=0
  on guest "$dyad" echo robot/secret --graph "${at[guest]}" --count 1 --wait 2 > "$out/refused_echo.txt" 2>&1 || refused_echo=$?
  on guest "$dyad" pub robot/state --graph "${at[guest]}" '{value: 1}' --wait 2 > "$out/refused_pub.txt" 2>&1 || refused_pub=$?
  local refused_host=0
  if [ "$mode" = exports ]; then
    on guest "$dyad" echo robot/state --graph "${at[guest]}" --host lab --count 1 --wait 2 > "$out/refused_host.txt" 2>&1 ||
      refused_host=$?
  fi
  local codes=() p
  for p in "${pids[@]}"; do
    c=0; wait "$p" || c=$?
    codes+=("$c")
  done
  local code_lab=0 code_rec=0
  wait "$lab_pid" || code_lab=$?
  wait "$rec_pid" || code_rec=$?
  echo "secure_hosts $mode: launchers exit $code_lab (lab) $code_rec (rec); tools exit: echo ${codes[0]}, record ${codes[1]}, pub ${codes[2]}, bag play ${codes[3]}, unsecured echo ${codes[4]}; refused: echo $refused_echo, pub $refused_pub"
  check() { if ! eval "$2"; then echo "secure_hosts $mode: NOT: $1"; ok=0; else echo "secure_hosts $mode: ok: $1"; fi; }
  check "both launchers exit 0" '[ $code_lab = 0 ] && [ $code_rec = 0 ]'
  check "dyad echo (guest) received robot/state" 'grep -q "\"value\"" "$out/echo.txt"'
  check "dyad record (guest) recorded robot/state" \
    '"$dyad" bag info "$out/guest.mcap" > "$out/guest_info.txt" 2>&1 && grep -Eq "robot/state.* [1-9][0-9]* (msgs|messages|samples)|robot/state +[1-9]" "$out/guest_info.txt"'
  check "dyad pub (guest) reached the graph's sink (value 4242)" 'grep -q "^4242 " "$out/sink.txt"'
  check "dyad bag play (guest) reached the graph's sink (values from 7000)" 'grep -q "^70[01][0-9] " "$out/sink.txt"'
  check "the graph's recording holds the guests' samples" \
    '"$dyad" bag export "$out/visit.mcap" --csv "$out/visit_csv" > /dev/null 2>&1 && grep -q ",4242" "$out/visit_csv/human_input.csv" && grep -q ",7000" "$out/visit_csv/human_input.csv"'
  check "dyad echo robot/secret refused (exit 2), naming security.guests.subscribe and the graph file" \
    '[ $refused_echo = 2 ] && grep -q "security.guests.subscribe (.*visit_secured.yaml:" "$out/refused_echo.txt"'
  check "dyad pub robot/state refused (exit 2), naming security.guests.publish and the graph file" \
    '[ $refused_pub = 2 ] && grep -q "security.guests.publish (.*visit_secured.yaml:" "$out/refused_pub.txt"'
  check "an unsecured tool heard nothing" '! grep -q "\"value\"" "$out/open_echo.txt"'
  if [ "$mode" = exports ]; then
    check "each machine holds only its identities, and no CA key" \
      '[ "$(ls "$out/lab/keys/identities" | tr "\n" " ")" = "host.lab process.arm " ] &&
       [ "$(ls "$out/rec/keys/identities" | tr "\n" " ")" = "host.rec process.ctl " ] &&
       [ "$(ls "$out/guest/keys/identities" | tr "\n" " ")" = "guest " ] &&
       ! find "$out/lab" "$out/rec" "$out/guest" -name "*.key.pem" | grep -q .'
    check "lab's launcher, given no --host, ran as host lab from its export and said so" \
      'grep -q "dyad run: running as host .lab., the host keystore .*/lab/keys was exported for" "$out/lab.log"'
    check "dyad echo --host lab on guest refused (exit 2), naming host.lab and the export that gives it" \
      '[ $refused_host = 2 ] && grep -q "identity .host.lab. is not in keystore .*--host lab OUT" "$out/refused_host.txt"'
  fi
  if [ $ok = 0 ]; then
    for f in echo record pub play open_echo refused_echo refused_pub refused_host lab rec; do
      echo "----- $f:"; tail -5 "$out/$f".* 2> /dev/null || true
    done
    failures+=("$mode"); return 0
  fi
  [ "$mode" = exports ] && echo "PASS: secure_hosts exports: each machine holding only its own export of the keystore, the graph ran and the guest visited it as in guests; another's identity was refused naming the export"
  echo "PASS: secure_hosts $mode: from a machine that is none of the graph's hosts, echo, record, pub and bag play visit as its guest within its grant; outside it they are refused naming the key; an unsecured tool hears nothing"
}

# --- starts ---------------------------------------------------------------------------------------
# One round: the ring graph G (secured or open) started on lab, mind and rec at the same instant.
# Appends "round ok start_ms host_tool_ms guest_tool_ms" to $out/rounds_$kind.txt (-1: failed).
start_round() {
  local kind=$1 i=$2 out=$3 G=$4 h t0 code ok=1 first last=0 s
  declare -A lpid
  local r=$out/$kind-$i
  mkdir -p "$r"
  t0=$(now_ms)
  local sets=()
  for h in lab mind rec; do sets+=(--set "sink_$h.file=$r/sink_$h.txt"); done
  for h in lab mind rec; do
    on "$h" "$dyad" run "$G" --host "$h" --duration 14 --quiet "${sets[@]}" > "$r/$h.log" 2>&1 &
    lpid[$h]=$!; started+=($!)
  done
  # The tools join the running graph: once every sink has its first sample (or at 50 s).
  local deadline=$((SECONDS + 50))
  while [ $SECONDS -lt $deadline ]; do
    s=0
    for h in lab mind rec; do [ -s "$r/sink_$h.txt" ] && s=$((s + 1)); done
    [ $s = 3 ] && break
    sleep 0.1
  done
  local t1 tp gp
  t1=$(now_ms)
  on lab "$dyad" echo ring/c --graph "$G" --host lab --count 1 --wait 10 --duration 12 > "$r/host_tool.txt" 2>&1 &
  tp=$!; started+=($!)
  on guest "$dyad" echo ring/a --graph "$G" --count 1 --wait 10 --duration 12 > "$r/guest_tool.txt" 2>&1 &
  gp=$!; started+=($!)
  wait "$tp" "$gp" || true
  for h in lab mind rec; do
    code=0; wait "${lpid[$h]}" || code=$?
    [ $code = 0 ] || { ok=0; echo "secure_hosts starts: $kind round $i: $h exited $code: $(grep -v '^$' "$r/$h.log" | tail -2 | tr '\n' ' ')"; }
  done
  for h in lab mind rec; do
    first=$(awk 'NR == 1 {print substr($4, 1, length($4) - 6)}' "$r/sink_$h.txt" 2> /dev/null)
    if [ -z "$first" ]; then ok=0; echo "secure_hosts starts: $kind round $i: the sink on $h received nothing"; continue; fi
    [ "$first" -gt "$last" ] && last=$first
  done
  local start_ms=-1
  [ $ok = 1 ] && start_ms=$((last - t0))
  echo "$i $ok $start_ms $(tool_ms "$r/host_tool.txt" "$t1") $(tool_ms "$r/guest_tool.txt" "$t1")" >> "$out/rounds_$kind.txt"
  echo "secure_hosts starts: $kind round $i: $(tail -1 "$out/rounds_$kind.txt" | awk '{printf "start %s, time to start %s ms, host tool %s ms, guest tool %s ms", ($2 ? "ok" : "FAILED"), $3, $4, $5}')"
}

# The time from t1 (ms) to a tool's first sample (the line's stamp_ns is the writer's; the file's
# change time is when the tool printed it); -1 when it received nothing.
tool_ms() {
  grep -q '"value"' "$1" || { echo -1; return; }
  echo $(($(date -r "$1" +%s%3N) - $2))
}

run_starts() {
  local n=${1#:} out=$work/starts kind i sec hog=() p
  [ -n "$n" ] || n=20
  mkdir -p "$out"
  for kind in secured open; do
    sec=()
    [ $kind = secured ] && sec=("security: {keystore: keys, guests: {subscribe: ['ring/*']}}")
    {
      printf '%s\n' "graph: ring" "clock: wall" \
        "network: {discovery: peers, hosts: {lab: ${addr[lab]}, mind: ${addr[mind]}, rec: ${addr[rec]}}${SECURE_HOSTS_NETWORK:+, $SECURE_HOSTS_NETWORK}}" "${sec[@]}" \
        "processes:" "  a: {host: lab}" "  b: {host: mind}" "  c: {host: rec}" "components:"
      # a (lab) -> b (mind) -> c (rec) -> a: each process writes one topic and reads another.
      printf '%s\n' "  src_lab: {type: counter_source, rate_hz: 20, process: a, outputs: {out: ring/a}}" \
        "  sink_mind: {type: counter_sink, trigger: in, process: b, params: {file: x}, inputs: {in: ring/a}}" \
        "  src_mind: {type: counter_source, rate_hz: 20, process: b, outputs: {out: ring/b}}" \
        "  sink_rec: {type: counter_sink, trigger: in, process: c, params: {file: x}, inputs: {in: ring/b}}" \
        "  src_rec: {type: counter_source, rate_hz: 20, process: c, outputs: {out: ring/c}}" \
        "  sink_lab: {type: counter_sink, trigger: in, process: a, params: {file: x}, inputs: {in: ring/c}}"
    } > "$out/ring_$kind.yaml"
  done
  "$dyad" security init "$out/keys" --graph "$out/ring_secured.yaml" > "$out/init.log" 2>&1 ||
    { cat "$out/init.log"; fail "starts: dyad security init failed"; }
  if [ "${SECURE_HOSTS_HOG:-1}" != 0 ]; then
    for p in $(seq "$(nproc)"); do
      yes > /dev/null &
      hog+=($!); started+=($!)
    done
    echo "secure_hosts starts: a CPU hog on each of $(nproc) cores (yes > /dev/null: pids ${hog[*]}); load $(cut -d' ' -f1-3 /proc/loadavg)"
  fi
  for kind in ${SECURE_HOSTS_KINDS:-secured open}; do
    : > "$out/rounds_$kind.txt"
    for ((i = 1; i <= n; i++)); do start_round "$kind" "$i" "$out" "$out/ring_$kind.yaml"; done
  done
  [ ${#hog[@]} = 0 ] || kill "${hog[@]}" 2> /dev/null || true
  python3 - "$out" "$n" <<'PY' | tee "$out/table.txt"
import statistics, sys
out, n = sys.argv[1], int(sys.argv[2])
def col(rows, k):
    return [r[k] for r in rows if r[k] >= 0]
def fmt(v):
    return f'{statistics.median(v) / 1000:.2f} / {max(v) / 1000:.2f} s' if v else '-'
print('| | starts ok | time to start, median / max | host tool ok | its first sample, median / max | guest tool ok | its first sample, median / max |')
print('| --- | --- | --- | --- | --- | --- | --- |')
ok = True
for kind in ('secured', 'open'):
    try:
        rows = [[int(x) for x in line.split()] for line in open(f'{out}/rounds_{kind}.txt')]
    except FileNotFoundError:
        continue  # (SECURE_HOSTS_KINDS left it out)
    starts, host, guest = sum(r[1] for r in rows), col(rows, 3), col(rows, 4)
    print(f'| {kind} | {starts} / {n} | {fmt(col(rows, 2))} | {len(host)} / {n} | {fmt(host)} | {len(guest)} / {n} | {fmt(guest)} |')
    ok &= starts == n and len(host) == n and len(guest) == n
sys.exit(0 if ok else 1)
PY
  if [ "${PIPESTATUS[0]}" != 0 ]; then
    failures+=("starts"); return 0
  fi
  echo "PASS: secure_hosts starts: every round of $n started, secured and open, and every tool received"
}

failures=()
for mode in "${modes[@]}"; do
  case $mode in
    guests | exports) run_guests "$mode" ;;
    starts*) run_starts "${mode#starts}" ;;
  esac
done
echo "secure_hosts: ${#modes[@]} mode(s) in $SECONDS s, ${#failures[@]} failed"
[ ${#failures[@]} = 0 ] || fail "failed mode(s): ${failures[*]}"
