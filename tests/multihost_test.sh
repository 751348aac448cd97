#!/usr/bin/env bash
# configs/split.yaml on three "machines": network namespaces lab, mind and rec (10.77.0.1-3/24),
# each joined by a veth pair to a Linux bridge in a fourth namespace. The three launchers
# (`dyad run configs/split.yaml --host H --steps 300`, the same --set everywhere) start one per
# namespace, rec first and lab last, 2 s apart; each must exit 0 within the time limit, and the
# recording made on rec must be complete, with every topic's sequence numbers contiguous from 1
# per writer (nothing lost between the hosts) and at least 300 human/input samples. Once per
# discovery MODE (a failed mode does not stop the next; the exit status is 1 if any failed):
#   multicast  the default: SPDP over multicast (the probe first proves multicast crosses the bridge);
#              mind's clock lies by +20 ms (DYAD_TEST_CLOCK_OFFSET_MS): `dyad status` run from rec
#              mid-run must list the three processes (host, pid, running) and measure the lie
#              within 1 ms both ways, and lab and rec must warn about it
#   peers      static peers from network.hosts; an nftables rule in every host drops all IPv4
#              multicast (224.0.0.0/4, in and out), so only unicast can work
#   server     a discovery server on lab:11811 (started by lab's launcher); multicast dropped too
#   tcp        static peers over TCP (each process listens on its tcp_port): all UDP between the
#              hosts dropped by nftables, so only TCP can work
#   faults     multicast, and two faults: `kill -9` of mind's process about step 100 (its
#              launcher restarts it: restart: on-failure) and mind's link down for 5 s about step
#              200. Checked: every launcher exits 0; lab's and rec's topics lose nothing; the
#              intentions resume after the restart (first one within 2.5 s of the kill) and after
#              the link is back, the gap on mind's topic only; no command moves further than
#              the mixer's max_step (5) from the one before.
#   failure[:D] multicast (or discovery mode D, as above: failure:tcp), mind without restarts (--set processes.mind.restart=never) and
#              `kill -9` of mind's process about step 100: mind's launcher exits 137 naming it;
#              lab's and rec's launchers hear of it (their launchers' link, dyad/processes) and
#              exit 1 within 10 s of the kill, naming mind and its host, their processes stopped
#              cleanly: rec's recording is complete and holds mind's "failed" announcement.
#   cut:D:H:S  discovery mode D (multicast, peers, server or tcp, as above), and host H's cable
#              pulled (its eth0 down) for S seconds about step 100. Checked: every launcher
#              exits 0; in the recording (on rec), every writer's samples are contiguous before
#              the cut and again from 2 s after the cable's return to the end of the run (none
#              stops), and no gap ends later than 2.2 s after the return; what was lost is
#              printed per writer. `matrix` expands to every D x H x (1, 3, 7 s) and the
#              server's race (4.5 s); MODE*N repeats a mode (e.g. cut:server:rec:3*10).
#   local      a one-process wall-clock graph with no network section on lab: `dyad echo` on
#              lab receives its topic (loopback), while from rec a watcher sending unicast
#              discovery straight to lab's address receives nothing; the same graph with `network: {scope: lan}`
#              is seen from rec (so the check can fail)
#   secure     DDS Security (`security:`, keystore from `dyad security init`): a graph on lab (arm:
#              counter_sink and recorder of robot/command) and rec (a source named plaintextmarker
#              writes robot/command); from mind an intruder with no identity and one with an
#              identity of another CA (a valid keystore of the same graph) publish robot/command
#              into the run and watch it. Checked: both launchers exit 0; the recording on lab is
#              complete with one writer, contiguous; the sink on lab never received an intruder's
#              sample (its file lists every sample's writer); the intruders' watcher heard nothing;
#              a capture on the bridge port of lab saw no packet with "plaintextmarker". The same graph without
#              security: the intruder's samples reach the sink and the marker is on the wire (so
#              the checks can fail)
#   net        (for debugging) only the namespaces and the UDP probe, no dyad run
# Needs root, `ip netns` and `nft` (skipped, exit 77, otherwise). Leaves nothing behind: the EXIT
# trap kills every process in its namespaces and deletes them (each host has a /dev/shm of its
# own, so killed Fast DDS processes leave no files in this machine's).
#   multihost_test.sh REPO BUILD_DIR WORK_DIR [MODE...]   (default: multicast peers server tcp faults failure)
# MULTIHOST_TIMEOUT=S: how long the three launchers of one mode may take (default 120 s);
# MULTIHOST_STAGGER=S: the time between the starts of rec, mind and lab (default 2 s, 0: at once);
# MULTIHOST_SHARED_SHM=1: the hosts share this machine's /dev/shm (default: one tmpfs each).
set -euo pipefail
[ $# -ge 3 ] || { echo "usage: multihost_test.sh REPO BUILD_DIR WORK_DIR [multicast|peers|server|tcp|faults|failure[:D]|cut:D:H:S|local|secure|matrix|net|MODE*N...]" >&2; exit 2; }
repo=$(cd "$1" && pwd) build=$(cd "$2" && pwd) work=$3
shift 3
modes=()
# matrix: every discovery mode x whose cable x 1 s, 3 s, past the lease (7 s), and the server's
# race (4.5 s: the lease ends as the cable returns); MODE*N: MODE N times.
for mode in "$@"; do
  if [ "$mode" = matrix ]; then
    for d in multicast peers server tcp; do
      for h in lab mind rec; do
        for s in 1 3 7; do modes+=("cut:$d:$h:$s"); done
        [ $d = server ] && modes+=("cut:$d:$h:4.5")
      done
    done
  elif [[ $mode =~ ^(.+)\*([0-9]+)$ ]]; then
    for ((i = 0; i < BASH_REMATCH[2]; i++)); do modes+=("${BASH_REMATCH[1]}"); done
  else
    modes+=("$mode")
  fi
done
[ ${#modes[@]} -gt 0 ] || modes=(multicast peers server tcp faults failure)
for mode in "${modes[@]}"; do
  case $mode in
    multicast | peers | server | tcp | faults | failure | local | secure | net) ;;
    failure:*) [[ $mode =~ ^failure:(multicast|peers|server|tcp)$ ]] ||
                 { echo "bad mode '$mode': failure:DISCOVERY (multicast|peers|server|tcp)" >&2; exit 2; } ;;
    cut:*) [[ $mode =~ ^cut:(multicast|peers|server|tcp):(lab|mind|rec):[0-9]+(\.[0-9]+)?$ ]] ||
             { echo "bad mode '$mode': cut:DISCOVERY:HOST:SECONDS (DISCOVERY multicast|peers|server|tcp, HOST lab|mind|rec)" >&2; exit 2; } ;;
    *) echo "unknown mode '$mode'" >&2; exit 2 ;;
  esac
done
dyad=$build/bin/dyad
timeout_s=${MULTIHOST_TIMEOUT:-120}
stagger=${MULTIHOST_STAGGER:-2}
skip() { echo "SKIP: multihost: $*"; exit 77; }
fail() { echo "FAIL: multihost: $*" >&2; exit 1; }

[ "$(id -u)" = 0 ] || skip "needs root (it creates network namespaces)"
command -v ip > /dev/null && ip netns list > /dev/null 2>&1 || skip "no 'ip netns' (iproute2)"
command -v nft > /dev/null || skip "no 'nft' (nftables)"
command -v python3 > /dev/null || skip "no python3"
[ "${modes[*]}" = net ] || [ -x "$dyad" ] || fail "no dyad at $dyad"

hosts=(lab mind rec)
declare -A addr
addr=([lab]=10.77.0.1 [mind]=10.77.0.2 [rec]=10.77.0.3)
source "$repo/tests/support/netns_test.sh"
netns_names dyadmh

rm -rf "$work"
mkdir -p "$work"
work=$(cd "$work" && pwd)
stamp=$work/.start
touch "$stamp"

# Kills what runs in our namespaces and deletes them. With MULTIHOST_SHARED_SHM=1 also removes
# the new Fast DDS shared-memory files that no live process maps (a killed participant leaves its
# segments and locks behind); otherwise each host's own tmpfs went with its last process.
cleanup() {
  local code=$? f base
  set +e
  trap - EXIT INT TERM
  netns_stop multihost
  if [ -f "$stamp" ] && [ "${MULTIHOST_SHARED_SHM:-0}" = 1 ]; then
    local mapped
    mapped=$(cat /proc/[0-9]*/maps 2> /dev/null | grep -o '/dev/shm/[^ ]*' | sort -u)
    while IFS= read -r f; do
      [ -n "$f" ] || continue
      base=${f%_el}; base=${base%_sl}; base=${base%_mutex}
      grep -qxF "$base" <<< "$mapped" || rm -f "$f"
    done < <(find /dev/shm -maxdepth 1 \( -name 'fastrtps_*' -o -name 'sem.fastrtps_*' -o -name 'fast_datasharing_*' \) \
               -newer "$stamp" 2> /dev/null)
  fi
  exit "$code"
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

# --- the network: a bridge in $sw, one veth pair per host -----------------------------------------
# A step that fails here is a limit of this machine (no CAP_NET_ADMIN, no bridge or veth driver):
# skipped, with the reason. IGMP snooping off: with no querier on this bridge a group's membership
# could age out (260 s) and a long run would lose multicast discovery halfway; a plain flooding
# switch is what we want.
netns_network mcast_snooping 0
netns_setup ip netns exec "$sw" nft add table ip dyad_multihost_probe  # nf_tables works here
netns_setup ip netns exec "$sw" nft delete table ip dyad_multihost_probe
# No default route in the namespaces: without this one, a send to a multicast group fails
# (ENETUNREACH) unless the socket names its interface.
for h in "${hosts[@]}"; do netns_setup ip -n "${ns[$h]}" route add 224.0.0.0/4 dev eth0; done
echo "multihost: namespaces ${made[*]}: ${addr[lab]} lab, ${addr[mind]} mind, ${addr[rec]} rec on a bridge"

# --- the probe: UDP unicast and multicast between every pair of hosts -----------------------------
# (ping is not installed everywhere; UDP is what Fast DDS uses anyway.) Each host listens on
# 17400 and on the group 239.255.0.77; each sends to the two others and to the group, a few times.
cat > "$work/probe.py" <<'PY'
import socket, struct, sys, time
role, me = sys.argv[1], sys.argv[2]
others = sys.argv[3].split(',')
group, port = '239.255.0.77', 17400
if role == 'recv':
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    s.bind(('', port))
    s.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP,
                 struct.pack('4s4s', socket.inet_aton(group), socket.inet_aton(me)))
    want = {f'{kind} {o}' for o in others for kind in ('unicast', 'multicast')}
    got, end = set(), time.time() + 6
    s.settimeout(0.2)
    print('ready', flush=True)
    while time.time() < end and not want <= got:
        try:
            got.add(s.recv(100).decode())
        except socket.timeout:
            pass
    for w in sorted(want):
        print(('ok      ' if w in got else 'MISSING ') + w + ' -> ' + me)
    sys.exit(0 if want <= got else 1)
else:
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 1)
    for _ in range(10):
        for o in others:
            s.sendto(f'unicast {me}'.encode(), (o, port))
        try:
            s.sendto(f'multicast {me}'.encode(), (group, port))
        except OSError as e:
            print(f'multicast send from {me}: {e}', file=sys.stderr)
        time.sleep(0.3)
PY
probe() {
  local h o others p rc=0
  declare -A rpid
  for h in "${hosts[@]}"; do
    others=""
    for o in "${hosts[@]}"; do [ "$o" = "$h" ] || others+=${others:+,}${addr[$o]}; done
    ip netns exec "${ns[$h]}" python3 "$work/probe.py" recv "${addr[$h]}" "$others" > "$work/probe_$h.out" 2>&1 &
    rpid[$h]=$!; started+=($!)
  done
  for h in "${hosts[@]}"; do
    for _ in $(seq 50); do grep -q ready "$work/probe_$h.out" 2> /dev/null && break; sleep 0.1; done
  done
  for h in "${hosts[@]}"; do
    others=""
    for o in "${hosts[@]}"; do [ "$o" = "$h" ] || others+=${others:+,}${addr[$o]}; done
    ip netns exec "${ns[$h]}" python3 "$work/probe.py" send "${addr[$h]}" "$others" &
    started+=($!)
  done
  for h in "${hosts[@]}"; do wait "${rpid[$h]}" || rc=1; done
  wait
  for h in "${hosts[@]}"; do grep -v '^ready' "$work/probe_$h.out" | sed "s/^/multihost: probe: /"; done
  return $rc
}
if probe; then
  echo "multihost: UDP unicast and multicast reach every host from every other"
elif grep -q 'MISSING unicast' "$work"/probe_*.out; then
  fail "UDP unicast between the namespaces does not work (see above)"
elif [[ " ${modes[*]} " == *" multicast "* ]]; then
  fail "multicast does not cross the bridge between the namespaces (unicast does; see above)"
else
  echo "multihost: multicast does not cross the bridge (not needed by the modes asked for)"
fi

# --- no multicast: an nftables table in each host namespace ---------------------------------------
# Its counters, printed after the run: UDP to a group is what Fast DDS would send (SPDP on
# 239.255.0.1); the other rule counts the rest, the kernel's own IGMP membership reports.
# A dropped send fails with EPERM in the sender.
# block_multicast [udp]: with `udp` (tcp mode) also every UDP datagram not on loopback, as on a
# network that passes TCP only.
block_multicast() {
  local h extra=""
  [ "${1:-}" = udp ] && extra=1
  for h in "${hosts[@]}"; do
    {
      echo 'table ip dyad_multihost {'
      for chain in input output; do
        local dev=iifname
        [ $chain = output ] && dev=oifname
        echo "  chain $chain {"
        echo "    type filter hook $chain priority 0; policy accept;"
        echo '    ip daddr 224.0.0.0/4 meta l4proto udp counter drop'
        echo '    ip daddr 224.0.0.0/4 counter drop'
        [ -n "$extra" ] && echo "    $dev != \"lo\" meta l4proto udp counter drop"
        echo '  }'
      done
      echo '}'
    } | ip netns exec "${ns[$h]}" nft -f -
  done
}
unblock_multicast() {
  local h
  for h in "${hosts[@]}"; do ip netns exec "${ns[$h]}" nft delete table ip dyad_multihost; done
}
print_drops() {
  local h
  for h in "${hosts[@]}"; do
    ip netns exec "${ns[$h]}" nft list table ip dyad_multihost |
      awk -v h="$h" '/chain/ { c = $2 }
        /counter/ { for (i = 1; i < NF; i++) if ($i == "packets") n = $(i + 1)
                    if (/udp/) u = n; else printf "multihost: %s %-6s multicast dropped: %s UDP, %s other (IGMP)\n", h, c, u, n }'
  done
}

# --- the models (quality does not matter: 20 epochs) -------------------------------------------------
dataset=$work/data/analytic model=$work/models/demo.dpvrnn observer=$work/models/demo.dobs
make_models() {
  [ -f "$observer" ] && return
  mkdir -p "$work/data" "$work/models"
  local t0=$SECONDS
  { "$dyad" generate dataset --out "$dataset" &&
    "$dyad" train "$repo/configs/train/demo.yaml" --set "dataset=$dataset" --set "output=$model" \
      --set epochs=20 --set log_every=20 &&
    "$dyad" train-observer "$model" -o "$observer" --epochs 20; } > "$work/models.log" 2>&1 ||
    { cat "$work/models.log"; fail "could not make the data set and models"; }
  echo "multihost: data set, model and observer made in $((SECONDS - t0)) s"
}

# --- the recording's check ---------------------------------------------------------------------------
cat > "$work/check.py" <<'PY'
# Per topic and writer (header.source): sequence numbers contiguous from 1, no gap, no repeat;
# human/input has at least MIN samples. Reads the CSVs of `dyad bag export --csv DIR`.
import csv, os, sys
folder, minimum = sys.argv[1], int(sys.argv[2])
topics = sys.argv[3:] or ['human/input', 'robot/intention', 'robot/command', 'robot/state', 'observer/labels']
ok = True
for topic in topics:
    path = os.path.join(folder, topic.replace('/', '_') + '.csv')
    if not os.path.exists(path):
        print(f'{topic}: no {os.path.basename(path)} (files: {sorted(os.listdir(folder))})'); ok = False; continue
    with open(path, newline='') as f:
        reader = csv.DictReader(f)
        columns = reader.fieldnames or []
        def column(name):
            hits = [c for c in columns if c == 'header.' + name] or [c for c in columns if c.split('.')[-1] == name]
            return hits[0] if hits else None
        src, seq = column('source'), column('sequence_number')
        if not src or not seq:
            print(f'{topic}: no header source / sequence_number column in {columns}'); ok = False; continue
        writers = {}
        for row in reader:
            writers.setdefault(row[src], []).append(int(row[seq]))
    count = sum(len(v) for v in writers.values())
    parts = []
    for writer, seqs in sorted(writers.items()):
        parts.append(f'{writer or "(empty)"} {seqs[0]}..{seqs[-1]}')
        expected = list(range(1, len(seqs) + 1))
        if sorted(seqs) != expected:
            have = set(seqs)
            missing = [n for n in range(1, max(seqs) + 1) if n not in have]
            repeated = len(seqs) - len(have)
            print(f'{topic}: writer {writer!r}: {len(seqs)} samples, sequence numbers {min(seqs)}..{max(seqs)}, '
                  f'{len(missing)} missing (first: {missing[:10]}), {repeated} repeated')
            ok = False
        elif seqs != expected:
            print(f'{topic}: writer {writer!r}: complete, but recorded out of order')
    print(f'{topic}: {count} samples, {len(writers)} writer(s): {", ".join(parts)}')
    if count == 0:
        print(f'{topic}: no samples'); ok = False
    if topic == 'human/input' and count < minimum:
        print(f'{topic}: {count} samples, fewer than {minimum}'); ok = False
sys.exit(0 if ok else 1)
PY
# export_recording FILE.mcap OUT_DIR: the recording must be complete; its topics as CSVs in OUT_DIR.
export_recording() {
  local rec=$1 out=$2 info
  [ -f "$rec" ] || { echo "no recording at $rec"; return 1; }
  info=$("$dyad" bag info "$rec" 2>&1) || { echo "$info"; echo "dyad bag info failed"; return 1; }
  echo "$info" | grep -q "state:       complete" || { echo "$info"; echo "the recording is not complete"; return 1; }
  rm -rf "$out"
  "$dyad" bag export "$rec" --csv "$out" > "$out.log" 2>&1 || { cat "$out.log"; echo "dyad bag export failed"; return 1; }
}
# check_recording FILE.mcap OUT_DIR MIN_HUMAN_SAMPLES [TOPIC...]: prints the check; non-zero on a failure.
check_recording() {
  local rec=$1 out=$2 min=$3
  shift 3
  export_recording "$rec" "$out" || return 1
  python3 "$work/check.py" "$out" "$min" "$@"
}

# --- cut: a host's cable pulled mid-run -------------------------------------------------------------
cat > "$work/check_cut.py" <<'PY'
# The recording of a run in which a host's cable was out from DOWN to UP (wall ns). Per topic and
# writer (header.source, stamps on the writer's clock: the hosts share one here):
#   before the cut   sequence numbers contiguous from 1 (nothing lost while the network was whole)
#   after UP + 2 s   samples again, contiguous, to the end of the run (within 1 s of the last
#                    sample of any topic), and no gap that ends later than UP + 2.2 s (one
#                    sample period of slack): data flows again within 2 s of the cable's return;
#                    5 s when a process renewed its participant (dyad/health): discovery had
#                    forgotten it, and it waits 2.5 s of silence before it renews; with TCP
#                    (4th argument `tcp`) and an outage longer than the lease, the outage's length
#                    plus 1 s: the connections resume at their next retransmission, whose
#                    interval the kernel has doubled through the outage (docs/distributed.md)
# and prints what was lost around the cut (samples and seconds), per writer.
import csv, os, sys
folder, down, up = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
tcp = len(sys.argv) > 4 and sys.argv[4] == 'tcp'
LEASE_NS = 5_000_000_000  # configs/split.yaml: the default network.lease_s
topics = ['human/input', 'robot/intention', 'robot/command', 'robot/state', 'observer/labels']
writers = {}
for topic in topics:
    with open(os.path.join(folder, topic.replace('/', '_') + '.csv'), newline='') as f:
        for r in csv.DictReader(f):
            writers.setdefault((topic, r['header.source']), []).append(
                (int(r['header.sequence_number']), int(r['header.stamp_ns'])))
if not writers:
    print('no samples at all'); sys.exit(1)
end = max(s for samples in writers.values() for _, s in samples)
# A process forgotten by discovery as a whole heals by renewing its participant once it has heard
# no one for 2.5 s (docs/distributed.md): then the flow may resume up to 5 s after the return.
bound_ns, renewed = 2_200_000_000, []
health = os.path.join(folder, 'dyad_health.csv')
if os.path.exists(health):
    with open(health, newline='') as f:
        for r in csv.DictReader(f):
            print(f"health: {r['process_name']} {r['endpoint']} {r['topic']} {r['action']} "
                  f"(matched {r['matched']} of {r['expected']}, {float(r['starved_s']):.1f} s) "
                  f"at {(int(r['header.stamp_ns']) - up) * 1e-9:+.1f} s from the return")
            renewed += [r['process_name']] if r['endpoint'] == 'participant' and r['action'] == 'renewed' else []
why = f' (participant renewed by {", ".join(renewed)})' if renewed else ''
if renewed:
    bound_ns = 5_000_000_000
if tcp and up - down > LEASE_NS:
    bound_ns = max(bound_ns, up - down + 1_000_000_000)
    why = ' (tcp, longer than the lease: the kernel\'s retransmission backoff)'
# From here on every writer's samples must be contiguous: 2 s, or the TCP bound's.
settle_ns = bound_ns - 200_000_000 if tcp and up - down > LEASE_NS else 2_000_000_000
print(f'every writer must flow again within {bound_ns * 1e-9:.1f} s of the return' + why)
ok = True
for (topic, writer), samples in sorted(writers.items()):
    samples.sort()
    name = f'{topic} ({writer})'
    before = [q for q, s in samples if s < down - 500_000_000]
    after = [(q, s) for q, s in samples if s >= up + settle_ns]
    lost = [(a, b) for a, b in zip(samples, samples[1:]) if b[0] != a[0] + 1]
    for a, b in lost:
        if a[1] < up + settle_ns and b[1] > up + bound_ns:
            print(f'{name}: flowed again only {(b[1] - up) * 1e-9:.1f} s after the cable came back '
                  f'(more than {bound_ns * 1e-9:.1f} s)'); ok = False
    gaps = ', '.join(f'{b[0] - a[0] - 1} samples {(a[1] - down) * 1e-9:+.1f} s..{(b[1] - down) * 1e-9:+.1f} s' for a, b in lost)
    print(f'{name}: {len(samples)} samples {samples[0][0]}..{samples[-1][0]}; lost around the cut: {gaps or "none"}')
    if before != list(range(1, len(before) + 1)):
        print(f'{name}: samples lost before the cable was pulled'); ok = False
    if not after:
        print(f'{name}: NOTHING after the cable came back (+{settle_ns * 1e-9:.1f} s); last sample {(samples[-1][1] - up) * 1e-9:+.1f} s from its return'); ok = False
        continue
    seqs = [q for q, _ in after]
    if seqs != list(range(seqs[0], seqs[0] + len(seqs))):
        print(f'{name}: samples lost after the cable came back (+{settle_ns * 1e-9:.1f} s)'); ok = False
    if after[-1][1] < end - 1_000_000_000:
        print(f'{name}: stopped {(after[-1][1] - up) * 1e-9:.1f} s after the cable came back, '
              f'{(end - after[-1][1]) * 1e-9:.1f} s before the end of the run'); ok = False
sys.exit(0 if ok else 1)
PY

# cut_cable HOST SECONDS OUT: about step 100, HOST's cable is pulled (its eth0 set down inside the
# host, as `ip link set eth0 down` on a machine) for SECONDS, then put back, with the multicast
# route the kernel dropped with the link; writes the instants (wall ns) to OUT/cut.
cut_cable() {
  local host=$1 secs=$2 out=$3 t_down t_up
  sleep 12
  t_down=$(date +%s%N)
  ip -n "${ns[$host]}" link set eth0 down
  sleep "$secs"
  ip -n "${ns[$host]}" link set eth0 up
  ip -n "${ns[$host]}" route replace 224.0.0.0/4 dev eth0
  t_up=$(date +%s%N)
  echo "multihost: cut: $host's cable was out for $secs s"
  echo "$t_down $t_up" > "$out/cut"
}

# --- faults: what happened to mind, and what the recording must show ------------------------------
cat > "$work/check_faults.py" <<'PY'
# The recording of the faults run: lab's and rec's topics contiguous per writer (the one check of
# check.py); robot/intention (mind's): runs of sequence numbers, one per start of mind's process,
# a gap only while mind's link was down; the restart's first intention soon after the kill; no
# command further than MAX_STEP from the previous one.
import csv, math, os, sys
folder, kill_ns, down_ns, up_ns, max_step = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4]), float(sys.argv[5])
def rows(topic):
    with open(os.path.join(folder, topic.replace('/', '_') + '.csv'), newline='') as f:
        return list(csv.DictReader(f))
ok = True
intent = rows('robot/intention')
runs, run = [], []
for r in intent:
    seq, stamp = int(r['header.sequence_number']), int(r['header.stamp_ns'])
    if run and seq <= run[-1][0]:
        runs.append(run); run = []
    run.append((seq, stamp))
runs.append(run)
print(f'robot/intention: {len(intent)} samples in {len(runs)} run(s) of sequence numbers: ' +
      ', '.join(f'{r[0][0]}..{r[-1][0]}' for r in runs))
if len(runs) != 2:
    print('robot/intention: expected 2 runs (before the kill, after the restart)'); ok = False
else:
    before, after = runs
    restart_s = (after[0][1] - kill_ns) * 1e-9
    print(f'robot/intention: last before the kill {(before[-1][1] - kill_ns) * 1e-9:+.2f} s, '
          f'first after the restart {restart_s:+.2f} s from the kill')
    if not 0 < restart_s <= 2.5:
        print('robot/intention: the restarted mind took longer than 2.5 s to publish'); ok = False
    if after[0][0] != 1:
        print('robot/intention: the restarted writer does not start at 1'); ok = False
    gaps = [(a, b) for a, b in zip(after, after[1:]) if b[0] != a[0] + 1]
    for a, b in gaps:
        print(f'robot/intention: gap {a[0]}..{b[0]} ({b[0] - a[0] - 1} samples), '
              f'{(a[1] - down_ns) * 1e-9:+.2f} s to {(b[1] - down_ns) * 1e-9:+.2f} s from the link going down '
              f'(up after {(up_ns - down_ns) * 1e-9:.1f} s)')
        if not (down_ns - 1e9 <= a[1] and b[1] <= up_ns + 15e9):
            print('robot/intention: a gap outside the link outage'); ok = False
    if not gaps:
        print('robot/intention: no gap while the link was down'); ok = False
    if after[-1][1] < up_ns:
        print('robot/intention: nothing after the link came back'); ok = False
cmd = rows('robot/command')
worst = 0.0
for a, b in zip(cmd, cmd[1:]):
    worst = max(worst, math.hypot(float(b['x']) - float(a['x']), float(b['y']) - float(a['y'])))
print(f'robot/command: {len(cmd)} commands, largest step {worst:.3f} (max_step {max_step})')
if worst > max_step + 1e-6:
    print('robot/command: a commanded jump larger than max_step'); ok = False
sys.exit(0 if ok else 1)
PY

# inject_faults OUT: waits for the graph to run, kills mind's process (kill -9) about step 100,
# then takes mind's link down for 5 s about step 200; writes the instants (wall ns) to OUT/faults.
inject_faults() {
  local out=$1 p pid="" t_kill t_down t_up
  sleep 12  # after the last launcher: the start barrier (~2 s) and ~100 steps of 100 ms
  for p in $(ip netns pids "${ns[mind]}"); do
    tr '\0' ' ' < "/proc/$p/cmdline" 2> /dev/null | grep -q -- "--process mind " && pid=$p
  done
  [ -n "$pid" ] || { echo "multihost: faults: mind's process not found"; return; }
  t_kill=$(date +%s%N)
  kill -KILL "$pid"
  echo "multihost: faults: killed mind's process ($pid)"
  sleep 10
  t_down=$(date +%s%N)
  ip -n "$sw" link set vmind down
  sleep 5
  ip -n "$sw" link set vmind up
  t_up=$(date +%s%N)
  echo "multihost: faults: mind's link was down for 5 s"
  echo "$t_kill $t_down $t_up" > "$out/faults"
}

# kill_mind OUT: waits for the graph to run, kills mind's process (kill -9) about step 100; writes
# the instant (wall ns) to OUT/killed.
kill_mind() {
  local out=$1 p pid=""
  sleep 12
  for p in $(ip netns pids "${ns[mind]}"); do
    tr '\0' ' ' < "/proc/$p/cmdline" 2> /dev/null | grep -q -- "--process mind " && pid=$p
  done
  [ -n "$pid" ] || { echo "multihost: failure: mind's process not found"; return; }
  date +%s%N > "$out/killed"
  kill -KILL "$pid"
  echo "multihost: failure: killed mind's process ($pid)"
}

# --- one run of configs/split.yaml per mode --------------------------------------------------------
run_mode() {
  local mode=$1 out=$work/${2:-}${1//:/_} h code failed="" t0=$SECONDS
  declare -A lpid
  mkdir -p "$out"
  # net: the network's mode (what is blocked, which discovery); cut:NET:HOST:SECONDS names it.
  local net=$mode cut_host="" cut_s=""
  [[ $mode == cut:* ]] && IFS=: read -r _ net cut_host cut_s <<< "$mode"
  [ "$mode" = faults ] && net=multicast
  local failure=0
  [[ $mode == failure* ]] && failure=1 net=multicast
  [[ $mode == failure:* ]] && net=${mode#failure:}
  if [ "$net" = peers ] || [ "$net" = server ]; then block_multicast; fi
  [ "$net" = tcp ] && block_multicast udp
  local discovery=$net
  [ "$net" = tcp ] && discovery=peers
  local transport=shm+udp
  [ "$net" = tcp ] && transport=tcp
  local sets=(--set "network.discovery=$discovery" --set "network.transport=$transport" --set "human.dataset=$dataset" --set "mind.model=$model"
              --set "observer.model=$observer" --set "recorder.file=$out/split.mcap")
  [ $failure = 1 ] && sets+=(--set processes.mind.restart=never)
  # Each host gets its own /dev/shm (a tmpfs in the mount namespace of `ip netns exec`), as on
  # separate machines: nothing can pass through shared memory between hosts, and Fast DDS's
  # port files cannot collide with another host's or another test's. MULTIHOST_SHARED_SHM=1: no.
  local wrap=()
  [ "${MULTIHOST_SHARED_SHM:-0}" = 1 ] ||
    wrap=(sh -c 'mount -t tmpfs -o mode=1777,size=256m dyad_multihost /dev/shm && exec "$@"' sh)
  # rec first, lab last, $stagger s apart: the start barrier must hold the early ones, and the
  # later launchers find the recording rec has already opened (one file system here, as with a
  # shared home folder).
  local first=1
  for h in rec mind lab; do
    [ $first = 1 ] || sleep "$stagger"
    first=0
    # multicast: mind's clock lies by 20 ms (test only), for `dyad status` and the warning.
    local lie=""
    [ "$mode" = multicast ] && [ "$h" = mind ] && lie=20
    (cd "$out" && DYAD_TEST_CLOCK_OFFSET_MS=$lie exec ip netns exec "${ns[$h]}" "${wrap[@]}" "$dyad" run "$repo/configs/split.yaml" \
       --host "$h" --steps 300 --quiet --logs "$out/logs" "${sets[@]}") > "$out/$h.log" 2>&1 &
    lpid[$h]=$!; started+=($!)
  done
  local injector=""
  if [ "$mode" = faults ]; then
    inject_faults "$out" &
    injector=$!
  elif [ $failure = 1 ]; then
    kill_mind "$out" &
    injector=$!
  elif [ -n "$cut_host" ]; then
    cut_cable "$cut_host" "$cut_s" "$out" &
    injector=$!
  elif [ "$mode" = multicast ]; then
    # Mid-run, from rec: every process with its host and pid, and mind's lie measured.
    (sleep 10 && ip netns exec "${ns[rec]}" "$dyad" status --graph "$repo/configs/split.yaml" --wait 5 > "$out/status.txt" 2>&1) &
    injector=$!
  fi
  local deadline=$((SECONDS + timeout_s)) alive
  while :; do
    alive=""
    for h in "${hosts[@]}"; do kill -0 "${lpid[$h]}" 2> /dev/null && alive+=" $h"; done
    [ -z "$alive" ] && break
    if [ $SECONDS -ge $deadline ]; then
      echo "multihost: $mode: still running after $timeout_s s:$alive (killed; their threads' stacks, if gdb is here: $out/stacks-HOST.txt)"
      for h in $alive; do
        if command -v gdb > /dev/null; then
          for p in $(ip netns pids "${ns[$h]}"); do
            echo "=== pid $p: $(tr '\0' ' ' < "/proc/$p/cmdline" 2> /dev/null)"
            timeout 60 gdb -p "$p" -batch -ex "thread apply all bt 25" 2>&1 | grep -E '^Thread|^#'
          done > "$out/stacks-$h.txt" 2>&1
        fi
        ip netns pids "${ns[$h]}" | xargs -r kill -KILL 2> /dev/null || true
      done
      failed+=" timeout"
      break
    fi
    sleep 1
  done
  for h in "${hosts[@]}"; do
    code=0
    wait "${lpid[$h]}" || code=$?
    if [ $failure = 1 ]; then
      local want=1
      [ "$h" = mind ] && want=137
      if [ $code != $want ]; then
        echo "----- $mode: $h exited $code, expected $want; its launcher's output:"
        cat "$out/$h.log"
        failed+=" $h"
      fi
      echo "$code" > "$out/$h.code"
      continue
    fi
    if [ $code != 0 ]; then
      echo "----- $mode: $h exited $code; its launcher's output ($out/$h.log; each process's: $out/logs):"
      cat "$out/$h.log"
      failed+=" $h"
    fi
  done
  [ -z "$injector" ] || wait "$injector" || true
  echo "multihost: $mode: the launchers ended after $((SECONDS - t0)) s"
  if [ "$net" = peers ] || [ "$net" = server ] || [ "$net" = tcp ]; then
    print_drops
    unblock_multicast
  fi
  if [ -n "$failed" ]; then
    echo "FAIL: multihost $mode: launcher(s) failed:$failed" >&2
    failures+=("$mode"); return 0
  fi
  if [ "$mode" = multicast ] && ! python3 - "$out/status.txt" "$out/logs" <<'PY' | sed "s/^/multihost: status: /"; then
# `dyad status` lists lab, mind and rec with their hosts, pids and state; the offsets measured of
# mind (whose clock lies by +20 ms) are within 1 ms of it; the processes that measured it warned.
import os, re, sys
text = open(sys.argv[1]).read()
tolerance = float(os.environ.get('MULTIHOST_OFFSET_TOLERANCE_MS', '1'))
print(text.rstrip().replace('\n', '\nstatus| '))
ok = True
for p in ['lab', 'mind', 'rec']:
    if not re.search(rf'^split/{p}\s+{p}\s+\d+\s+running', text, re.M):
        print(f'{p}: not listed as running on host {p} with a pid'); ok = False
offsets = {(a, b): float(v) for a, b, v in re.findall(r'^\s+(\w+)\s+-> (\w+)\s+([+-][0-9.]+) ms', text, re.M)}
for (a, b), v in sorted(offsets.items()):
    want = 20.0 if b == 'mind' else -20.0 if a == 'mind' else 0.0
    good = abs(v - want) <= tolerance
    print(f'offset {a} -> {b}: {v:+.3f} ms (expected {want:+.0f} within {tolerance:g} ms): {"ok" if good else "WRONG"}')
    ok &= good
if len(offsets) != 6:
    print(f'{len(offsets)} offsets listed, expected 6 (every ordered pair of 3 processes)'); ok = False
logs = sys.argv[2]
for p in ['lab', 'rec']:
    log = open(os.path.join(logs, p + '.log')).read()
    if "[warn] clock: the clock of process 'mind' is +" not in log:
        print(f'{p}.log: no warning about mind\'s clock'); ok = False
sys.exit(0 if ok else 1)
PY
    echo "FAIL: multihost $mode: dyad status (see above)" >&2
    failures+=("$mode"); return 0
  fi
  if [ $failure = 1 ]; then
    local t_kill t_end ok=1
    t_kill=$(cat "$out/killed" 2> /dev/null) || { echo "FAIL: multihost $mode: mind was not killed" >&2; failures+=("$mode"); return 0; }
    grep -q "process 'mind' exited with 137 (SIGKILL)$" "$out/mind.log" || { echo "mind's launcher did not name mind's end"; ok=0; }
    for h in lab rec; do
      grep -q "process 'mind' on host 'mind' failed for good: stopping the processes of host '$h'" "$out/$h.log" ||
        { echo "$h's launcher did not say mind failed:"; cat "$out/$h.log"; ok=0; }
      t_end=$(stat -c %Y "$out/$h.code")
      echo "multihost: $mode: $h's launcher ended $((t_end - t_kill / 1000000000)) s after the kill"
      [ $((t_end - t_kill / 1000000000)) -le 10 ] || { echo "$h's launcher took longer than 10 s"; ok=0; }
    done
    local info
    info=$("$dyad" bag info "$out/split.mcap" 2>&1) || { echo "$info"; ok=0; }
    echo "$info" | grep -q "state:       complete" || { echo "$info"; echo "rec's recording is not complete"; ok=0; }
    "$dyad" bag export "$out/split.mcap" --csv "$out/csv" > "$out/csv.log" 2>&1 || { cat "$out/csv.log"; ok=0; }
    grep -q ",mind,mind,.*,failed," "$out/csv/dyad_processes.csv" 2> /dev/null ||
      { echo "no 'failed' state of mind in the recording's dyad/processes:"; head -3 "$out/csv/dyad_processes.csv" 2>&1; ok=0; }
    if [ $ok = 0 ]; then
      echo "FAIL: multihost $mode: see above" >&2
      failures+=("$mode"); return 0
    fi
    echo "PASS: multihost $mode: mind killed with no restart left: every host's launcher ended the run within 10 s, naming it; the recording is complete and holds the failure"
    return 0
  fi
  if [ "$mode" = faults ]; then
    local f
    f=$(cat "$out/faults" 2> /dev/null) || { echo "FAIL: multihost faults: the faults were not injected" >&2; failures+=("$mode"); return 0; }
    grep -q "process 'mind' exited with 137 (SIGKILL); restarting" "$out/mind.log" ||
      { cat "$out/mind.log"; echo "FAIL: multihost faults: mind's launcher did not restart it" >&2; failures+=("$mode"); return 0; }
    # lab's and rec's topics must lose nothing; mind's are checked for their runs and gap.
    if ! check_recording "$out/split.mcap" "$out/csv" 300 human/input robot/command robot/state observer/labels |
         sed "s/^/multihost: $mode: /" ||
       ! python3 "$work/check_faults.py" "$out/csv" $f 5 | sed "s/^/multihost: $mode: /"; then
      echo "FAIL: multihost $mode: the recording $out/split.mcap does not pass (see above)" >&2
      failures+=("$mode"); return 0
    fi
    echo "PASS: multihost faults: mind killed and restarted, its link cut for 5 s: the others lost nothing, intentions resumed"
    return 0
  fi
  if [ -n "$cut_host" ]; then
    local c
    c=$(cat "$out/cut" 2> /dev/null) || { echo "FAIL: multihost $mode: the cable was not pulled" >&2; failures+=("$mode"); return 0; }
    if ! export_recording "$out/split.mcap" "$out/csv" | sed "s/^/multihost: $mode: /" ||
       ! python3 "$work/check_cut.py" "$out/csv" $c "$net" | sed "s/^/multihost: $mode: /"; then
      echo "FAIL: multihost $mode: the recording $out/split.mcap does not pass (see above)" >&2
      failures+=("$mode"); return 0
    fi
    echo "PASS: multihost $mode: $cut_host's cable out for $cut_s s ($net): every topic flowed again in time (above), to the end"
    return 0
  fi
  if ! check_recording "$out/split.mcap" "$out/csv" 300 | sed "s/^/multihost: $mode: /"; then
    echo "FAIL: multihost $mode: the recording $out/split.mcap does not pass (see above)" >&2
    failures+=("$mode"); return 0
  fi
  echo "PASS: multihost $mode: 3 hosts, 300 steps, recording complete, no sample lost"
}

# local: who can see a graph that names no other machine (network.scope: local by default).
# Reports in `failures` as run_mode does.
run_local_mode() {
  local out=$work/$1local scope graph_pid seen
  mkdir -p "$out"
  for scope in local lan; do
    printf '%s\n' "graph: solo" "clock: wall" "network: {scope: $scope}" "components:" \
      "  src: {type: counter_source, rate_hz: 10, outputs: {out: subject/pointer}}" > "$out/solo_$scope.yaml"
  done
  # The intruder on rec: unicast discovery sent straight to lab's address (no multicast needed).
  printf '%s\n' "graph: solo" "network: {discovery: peers, peers: [${addr[lab]}]}" "components:" \
    "  src: {type: counter_source, rate_hz: 10, outputs: {out: subject/pointer}}" > "$out/intruder.yaml"
  for scope in local lan; do
    ip netns exec "${ns[lab]}" "$dyad" run "$out/solo_$scope.yaml" --duration 20 --quiet > "$out/solo_$scope.log" 2>&1 &
    graph_pid=$!; started+=($!)
    sleep 2
    # On lab, the watcher joins as the graph does (without --graph: local, as the default graph).
    local own=()
    [ $scope = lan ] && own=(--graph "$out/solo_lan.yaml")
    ip netns exec "${ns[lab]}" "$dyad" echo subject/pointer "${own[@]}" --count 1 --wait 4 > "$out/lab_topics_$scope.txt" 2>&1 || true
    ip netns exec "${ns[rec]}" "$dyad" echo subject/pointer --graph "$out/intruder.yaml" --count 1 --wait 6 \
      > "$out/rec_topics_$scope.txt" 2>&1 || true
    kill -INT "$graph_pid" 2> /dev/null || true
    wait "$graph_pid" 2> /dev/null || true
    if ! grep -q '"value"' "$out/lab_topics_$scope.txt"; then
      echo "FAIL: multihost local: scope $scope: lab's own watcher did not see the graph:" >&2
      cat "$out/lab_topics_$scope.txt" "$out/solo_$scope.log" >&2
      failures+=(local); return 0
    fi
    seen=0
    grep -q '"value"' "$out/rec_topics_$scope.txt" && seen=1
    if [ $scope = local ] && [ $seen = 1 ]; then
      echo "FAIL: multihost local: another machine saw the one-machine graph's topic:" >&2
      cat "$out/rec_topics_$scope.txt" >&2
      failures+=(local); return 0
    fi
    if [ $scope = lan ] && [ $seen = 0 ]; then
      echo "FAIL: multihost local: with network.scope lan the intruder saw nothing (the check could not fail):" >&2
      cat "$out/rec_topics_$scope.txt" >&2
      failures+=(local); return 0
    fi
  done
  echo "PASS: multihost local: a one-machine graph is seen on its machine only (and from rec with scope lan)"
}

# secure: see the header. One round with security, one without (the control).
run_secure_mode() {
  local out=$work/$1secure round sec i pids lab_pid rec_pid code_lab code_rec capture_pid marked
  mkdir -p "$out"
  local peers="network: {discovery: peers, hosts: {lab: ${addr[lab]}, rec: ${addr[rec]}}}"
  for round in secured open; do
    sec=()
    [ $round = secured ] && sec=("security: {keystore: keys}")
    printf '%s\n' "graph: guard" "clock: wall" "$peers" "${sec[@]}" "processes:" "  arm: {host: lab}" "  ctl: {host: rec}" \
      "components:" \
      "  sink: {type: counter_sink, trigger: in, process: arm, params: {file: $out/sink_$round.txt}, inputs: {in: robot/command}}" \
      "  rec: {type: recorder, rate_hz: 1, process: arm, params: {file: $out/guard_$round.mcap, topics: [robot/command]}}" \
      "  plaintextmarker: {type: counter_source, rate_hz: 20, process: ctl, outputs: {out: robot/command}}" \
      > "$out/guard_$round.yaml"
    # The intruder on mind: the same graph name and run, peers to lab and rec, its own writer.
    sec=()
    [ $round = secured ] && sec=("security: {keystore: other_keys}")
    printf '%s\n' "graph: guard" "clock: wall" "network: {discovery: peers, peers: [${addr[lab]}, ${addr[rec]}]}" "${sec[@]}" \
      "components:" "  intruder: {type: counter_source, rate_hz: 20, outputs: {out: robot/command}}" > "$out/intruder_$round.yaml"
  done
  "$dyad" security init "$out/keys" --graph "$out/guard_secured.yaml" > "$out/init.log" 2>&1 &&
    "$dyad" security init "$out/other_keys" --graph "$out/intruder_secured.yaml" >> "$out/init.log" 2>&1 ||
    { cat "$out/init.log" >&2; failures+=(secure); return 0; }
  for round in secured open; do
    ip netns exec "$sw" python3 "$repo/tests/capture_marker.py" plaintextmarker 12 vlab > "$out/capture_$round.txt" 2>&1 &
    capture_pid=$!; started+=($!)
    ip netns exec "${ns[lab]}" "$dyad" run "$out/guard_$round.yaml" --host lab --duration 20 --quiet > "$out/lab_$round.log" 2>&1 &
    lab_pid=$!; started+=($!)
    ip netns exec "${ns[rec]}" "$dyad" run "$out/guard_$round.yaml" --host rec --duration 20 --quiet > "$out/rec_$round.log" 2>&1 &
    rec_pid=$!; started+=($!)
    sleep 6
    # Against the secured graph, both intruders (none of its identities, another CA's); else the bare one.
    local intruders=(open)
    [ $round = secured ] && intruders=(open secured)
    pids=()
    for i in "${intruders[@]}"; do
      ip netns exec "${ns[mind]}" "$dyad" run "$out/intruder_$i.yaml" --run-id shared --duration 8 --quiet \
        > "$out/intruder_${i}_in_$round.log" 2>&1 &
      pids+=($!); started+=($!)
    done
    : > "$out/heard_$round.txt"
    for i in "${intruders[@]}"; do
      ip netns exec "${ns[mind]}" "$dyad" echo robot/command --graph "$out/intruder_$i.yaml" --run-id shared --count 1 --wait 6 \
        >> "$out/heard_$round.txt" 2>&1 || true
    done
    wait "${pids[@]}" 2> /dev/null || true
    code_lab=0; wait "$lab_pid" || code_lab=$?
    code_rec=0; wait "$rec_pid" || code_rec=$?
    wait "$capture_pid" || true
    marked=$(awk '/^packets/ {print $4}' "$out/capture_$round.txt")
    echo "multihost secure: $round: launchers exit $code_lab (lab) $code_rec (rec); $(grep '^packets' "$out/capture_$round.txt"); sink heard $(awk '{print $2}' "$out/sink_$round.txt" | sort | uniq -c | tr '\n' ' ')"
    if [ "$code_lab" != 0 ] || [ "$code_rec" != 0 ]; then
      echo "FAIL: multihost secure: $round: a launcher failed" >&2
      tail -5 "$out/lab_$round.log" "$out/rec_$round.log" >&2
      failures+=(secure); return 0
    fi
    if [ $round = secured ]; then
      if ! check_recording "$out/guard_$round.mcap" "$out/csv_$round" 0 robot/command > "$out/check_$round.txt" 2>&1 ||
        ! grep -q "robot/command: .* 1 writer(s): plaintextmarker 1\.\." "$out/check_$round.txt"; then
        echo "FAIL: multihost secure: the secured run's recording is incomplete or has another writer:" >&2
        cat "$out/check_$round.txt" >&2; failures+=(secure); return 0
      fi
      if grep -q " intruder " "$out/sink_$round.txt" || [ "$(grep -c ' plaintextmarker ' "$out/sink_$round.txt")" -lt 300 ]; then
        echo "FAIL: multihost secure: the arm's sink heard an intruder, or too little of its own writer" >&2
        failures+=(secure); return 0
      fi
      if grep -q '"value"' "$out/heard_$round.txt" || [ "${marked:-x}" != 0 ]; then
        echo "FAIL: multihost secure: an intruder heard the graph, or the marker crossed the bridge in clear ($marked packets)" >&2
        cat "$out/heard_$round.txt" >&2; failures+=(secure); return 0
      fi
    elif ! grep -q " intruder " "$out/sink_$round.txt" || ! grep -q '"value"' "$out/heard_$round.txt" || [ "${marked:-0}" = 0 ]; then
      echo "FAIL: multihost secure: without security the intruder was not heard, or did not hear, or no marker was seen (the checks could not fail)" >&2
      cat "$out/heard_$round.txt" "$out/capture_$round.txt" >&2; failures+=(secure); return 0
    fi
  done
  echo "PASS: multihost secure: intruders with no identity or another CA's neither reach the arm nor hear the graph; nothing in clear on the wire (without security they do, and it is)"
}

# run_mode reports a failure in `failures` (not by its status: under `||` or `if`, set -e would
# stop applying inside it).
failures=()
n=0
for mode in "${modes[@]}"; do
  [ "$mode" = net ] && { echo "PASS: multihost net: namespaces and probe"; continue; }
  n=$((n + 1))
  [ "$mode" = local ] && { run_local_mode "$n-"; continue; }
  [ "$mode" = secure ] && { run_secure_mode "$n-"; continue; }
  make_models
  run_mode "$mode" "$n-"
done
echo "multihost: ${#modes[@]} mode run(s) in $SECONDS s, ${#failures[@]} failed"
[ ${#failures[@]} = 0 ] || fail "failed mode(s): ${failures[*]}"
