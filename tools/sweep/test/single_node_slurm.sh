#!/usr/bin/env bash
# A Slurm cluster of one node on this machine, all of it in one folder: munged, slurmctld and
# slurmd from Debian's munge and slurm-wlm (22.05), on free loopback ports, as root (slurmd
# starts jobs as their users). Nothing in /etc is read or written; the system's own munge or
# Slurm, if any, is not touched.
#   bash single_node_slurm.sh start DIR   # prints `export SLURM_CONF=DIR/slurm.conf` when ready
#   bash single_node_slurm.sh stop DIR
#   bash single_node_slurm.sh leftovers DIR   # what of it is still running (stop ends it all)
# start exits 77 with the reason when this machine cannot run it (not root, not installed, a
# daemon that does not come up: its log is printed).
set -euo pipefail
what=$1
dir=$(mkdir -p "$2" && cd "$2" && pwd)
skip() { echo "SKIP: single-node Slurm: $*" >&2; exit 77; }

# The job steps' slurmstepd and the jobs' own processes (SLURM_JOB_ID set) of this Slurm, by
# their environment (SLURM_CONF names this folder's slurm.conf), one PID a line. Not this
# script, nor the shell that called it.
job_processes() {
  local p env
  for p in /proc/[0-9]*; do
    [ "${p#/proc/}" = $$ ] && continue
    env=$(tr '\0' '\n' 2> /dev/null < "$p/environ") || continue
    if [ "$(cat "$p/comm" 2> /dev/null)" = slurmstepd ]; then
      # Its environment or its open files (the node's log, its spool socket) say whose it is.
      if grep -qxF "SLURM_CONF=$dir/slurm.conf" <<< "$env" ||
        find "$p/fd" "$p/cwd" -maxdepth 1 -lname "$dir/*" 2> /dev/null | grep -q .; then echo "${p#/proc/}"; fi
    elif grep -qxF "SLURM_CONF=$dir/slurm.conf" <<< "$env" && grep -q '^SLURM_JOB_ID=' <<< "$env"; then
      echo "${p#/proc/}"
    fi
  done
  return 0
}

# Every process this Slurm started that is still there: its daemons, its job steps, its jobs.
leftovers() {
  job_processes
  local pid_file
  for pid_file in "$dir/slurmd.pid" "$dir/slurmctld.pid" "$dir/munge/munged.pid"; do
    [ -s "$pid_file" ] && kill -0 "$(cat "$pid_file")" 2> /dev/null && cat "$pid_file"
  done
  return 0
}

# Whether one of `pids` still runs (a zombie does not: its parent, maybe a container's init
# that reaps nothing, has yet to collect it).
any_running() {
  local pid state
  for pid in "$@"; do
    state=$(sed -n 's/.*) \(.\).*/\1/p' "/proc/$pid/stat" 2> /dev/null) || continue
    [ -n "$state" ] && [ "$state" != Z ] && return 0
  done
  return 1
}

# `pids` gone: SIGTERM, then SIGKILL after 10 s.
end_all() {
  [ $# -gt 0 ] || return 0
  kill "$@" 2> /dev/null || true
  for _ in $(seq 100); do
    any_running "$@" || return 0
    sleep 0.1
  done
  kill -KILL "$@" 2> /dev/null || true
}

# Every process it started gone when it returns, job steps included (a next start reuses the
# folder): the jobs cancelled while the controller can still end their steps, the daemons
# stopped, then whatever is left of them.
stop() {
  export SLURM_CONF=$dir/slurm.conf
  local jobs=""
  # (only a controller that runs: a client would wait for a stopped one)
  if [ -s "$dir/slurmctld.pid" ] && kill -0 "$(cat "$dir/slurmctld.pid")" 2> /dev/null; then
    jobs=$(squeue -h -o %i 2> /dev/null || true)
  fi
  if [ -n "$jobs" ]; then
    # shellcheck disable=SC2086
    scancel $jobs > /dev/null 2>&1 || true
    for _ in $(seq 100); do
      [ -z "$(job_processes)" ] && break
      sleep 0.1
    done
  fi
  if [ -s "$dir/slurmctld.pid" ] && kill -0 "$(cat "$dir/slurmctld.pid")" 2> /dev/null; then
    scontrol shutdown > /dev/null 2>&1 || true
  fi
  # shellcheck disable=SC2046
  end_all $(leftovers)
  # (a job step's process may outlive its slurmstepd a moment)
  # shellcheck disable=SC2046
  end_all $(leftovers)
}

free_port() {
  python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'
}

start() {
  [ "$(id -u)" = 0 ] || skip "needs root (slurmd runs jobs as their users)"
  for tool in munged slurmctld slurmd sbatch scontrol sinfo; do
    command -v "$tool" > /dev/null || [ -x "/usr/sbin/$tool" ] || skip "$tool not found (tools/setup.sh installs slurm-wlm and munge)"
  done
  stop
  rm -rf "$dir/munge" "$dir/state" "$dir/spool" "$dir/log"
  mkdir -p "$dir/munge" "$dir/state" "$dir/spool" "$dir/log"
  chmod 711 "$dir/munge"
  head -c 1024 /dev/urandom > "$dir/munge/munge.key"
  chmod 400 "$dir/munge/munge.key"
  /usr/sbin/munged --force --socket="$dir/munge/munge.socket" --key-file="$dir/munge/munge.key" \
    --log-file="$dir/log/munged.log" --pid-file="$dir/munge/munged.pid" --seed-file="$dir/munge/seed" ||
    { cat "$dir/log/munged.log" >&2; skip "munged did not start"; }
  cat > "$dir/slurm.conf" <<CONF
ClusterName=dyadtest
SlurmctldHost=localhost(127.0.0.1)
SlurmctldPort=$(free_port)
SlurmdPort=$(free_port)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$dir/munge/munge.socket
CredType=cred/munge
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
# No cgroups (containers and CI machines rarely delegate them): plain process tracking.
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
MpiDefault=none
NodeName=dyadnode NodeAddr=127.0.0.1 NodeHostname=$(hostname) CPUs=$(nproc) State=UNKNOWN
PartitionName=dyad Nodes=dyadnode Default=YES MaxTime=INFINITE State=UP
CONF
  export SLURM_CONF=$dir/slurm.conf
  /usr/sbin/slurmctld -i -f "$SLURM_CONF" || { cat "$dir/log/slurmctld.log" >&2; stop; skip "slurmctld did not start"; }
  /usr/sbin/slurmd -N dyadnode -f "$SLURM_CONF" || { cat "$dir/log/slurmd.log" >&2; stop; skip "slurmd did not start"; }
  for _ in $(seq 100); do
    [ "$(sinfo -h -o %t 2> /dev/null)" = idle ] && { echo "export SLURM_CONF=$SLURM_CONF"; return 0; }
    sleep 0.2
  done
  tail -20 "$dir/log/slurmctld.log" "$dir/log/slurmd.log" >&2
  stop
  skip "the node never became idle in 20 s"
}

case $what in
  start) start ;;
  stop) stop ;;
  leftovers) leftovers ;;
  *) echo "usage: single_node_slurm.sh start|stop|leftovers DIR" >&2; exit 2 ;;
esac
