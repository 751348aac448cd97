# tests/support/netns_test.sh: what the scripts that run dyad on several "machines" share
# (multihost_test.sh, secure_hosts_test.sh; source it; bash, set -e): one network namespace per
# host, each joined by a veth pair (its eth0) to a Linux bridge in a namespace of its own.
# The script first sets `work` (an absolute folder), `hosts` (an array), `addr` (an associative
# array: host -> IPv4 address, /24) and defines skip MESSAGE (exit 77). Then:
#   netns_names PREFIX   sets sw (the bridge's namespace) and ns[host] to PREFIX_<name>_$$, and
#                        deletes the namespaces of an earlier run named so whose pid is gone (it
#                        was killed before its trap ran), with what still ran in them
#   netns_stop NAME      for the EXIT trap: kills the pids in `started`, then everything running
#                        in the namespaces in `made` (up to 10 rounds), waits for `started` and
#                        deletes the namespaces, saying "NAME: could not delete ..." on stderr
#   netns_setup CMD...   runs CMD; if it fails (a limit of this machine: no CAP_NET_ADMIN, no
#                        bridge or veth driver), skips naming CMD and its error
#   netns_network [OPTION...]
#                        the bridge (br0 in $sw, made with the bridge OPTIONs, e.g. mcast_snooping 0)
#                        and each host's namespace, eth0 at its address, lo up; every namespace
#                        made is added to `made`
# Sets made=() and started=() (the script adds the pids of what it starts to `started`).
declare -A ns
made=() started=()

netns_names() {
  local prefix=$1 old h pattern
  sw=${prefix}_sw_$$
  for h in "${hosts[@]}"; do ns[$h]=${prefix}_${h}_$$; done
  pattern="^${prefix}_(sw$(printf '|%s' "${hosts[@]}"))_[0-9]+$"
  for old in $(ip netns list | awk '{print $1}' | grep -E "$pattern" || true); do
    if ! kill -0 "${old##*_}" 2> /dev/null; then
      ip netns pids "$old" 2> /dev/null | xargs -r kill -KILL 2> /dev/null || true
      ip netns del "$old" 2> /dev/null || true
    fi
  done
}

netns_stop() {
  local name=$1 n p i
  for p in "${started[@]}"; do kill -KILL "$p" 2> /dev/null; done
  for i in 1 2 3 4 5 6 7 8 9 10; do
    p=""
    for n in "${made[@]}"; do p+=$(ip netns pids "$n" 2> /dev/null); done
    [ -z "$p" ] && break
    echo "$p" | xargs -r kill -KILL 2> /dev/null
    sleep 0.3
  done
  for p in "${started[@]}"; do wait "$p" 2> /dev/null; done
  for n in "${made[@]}"; do ip netns del "$n" 2> /dev/null || echo "$name: could not delete namespace $n" >&2; done
}

netns_setup() { "$@" 2> "$work/netns.err" || skip "cannot set up the network: '$*': $(cat "$work/netns.err")"; }

netns_network() {
  local h n
  netns_setup ip netns add "$sw"
  made+=("$sw")
  netns_setup ip -n "$sw" link set lo up
  netns_setup ip -n "$sw" link add br0 type bridge "$@"
  netns_setup ip -n "$sw" link set br0 up
  for h in "${hosts[@]}"; do
    n=${ns[$h]}
    netns_setup ip netns add "$n"
    made+=("$n")
    netns_setup ip -n "$sw" link add "v$h" type veth peer name eth0 netns "$n"
    netns_setup ip -n "$sw" link set "v$h" master br0 up
    netns_setup ip -n "$n" link set lo up
    netns_setup ip -n "$n" addr add "${addr[$h]}/24" dev eth0
    netns_setup ip -n "$n" link set eth0 up
  done
}
