#!/usr/bin/env bash
# A throw-away single-node Slurm cluster on this machine, from Debian 12's packages
# (slurm-wlm 22.05 and munge, installed by scripts/setup.sh --deps), for the Slurm test
# (tests/python/test_slurm.py) and for trying deploy/slurm/ by hand.
#
#   tests/slurm/cluster.sh start [DIR]   start munged, slurmctld and slurmd with all their
#                                        state, sockets, logs and pid files in DIR (default: a
#                                        new mktemp -d); prints, for eval,
#                                          export SLURM_CONF=DIR/slurm.conf
#                                          export HERON_SLURM_DIR=DIR
#                                        once `sinfo` shows the node idle.
#   tests/slurm/cluster.sh stop DIR      cancel its jobs, stop its daemons, remove DIR
#   tests/slurm/cluster.sh logs DIR      print the daemons' logs (for failure reports)
#
#   eval "$(tests/slurm/cluster.sh start)"
#   sbatch --wrap hostname; squeue
#   tests/slurm/cluster.sh stop "$HERON_SLURM_DIR"
#
# Must run as root: slurmd launches jobs as the submitting user, which only root may do,
# and SlurmUser=root keeps every file owned by one user. Nothing in /etc is read or written:
# the Slurm commands and daemons find the configuration through SLURM_CONF, and munged
# gets its own key, socket, pid, log and seed files in DIR (slurm.conf's AuthInfo names
# that socket), so a munged or slurmd the system may run is not touched. The ports are
# free ones picked at start. No cgroups: processes are tracked through /proc
# (proctrack/linuxproc) and tasks are not bound (task/none), as a container allows.
#
# Layout of DIR: .heron-slurm-cluster (the mark `stop` checks before removing DIR), slurm.conf, munge/ (munge.key, munge.socket.2, pid, seed), ctld/
# (StateSaveLocation), spool/ (SlurmdSpoolDir), log/ (munged.log, slurmctld.log,
# slurmd.log and the daemons' stdout/stderr), *.pid.
set -euo pipefail

die() {
  echo "cluster.sh: $*" >&2
  exit 1
}

# Seconds to wait for the node to come up and for jobs to drain at stop.
START_TIMEOUT=${HERON_SLURM_START_TIMEOUT:-60}
STOP_TIMEOUT=${HERON_SLURM_STOP_TIMEOUT:-30}

need_tools() {
  local missing=()
  for t in munged mungekey slurmctld slurmd sinfo scontrol squeue scancel sbatch; do
    command -v "$t" >/dev/null 2>&1 || missing+=("$t")
  done
  [ ${#missing[@]} -eq 0 ] ||
    die "missing ${missing[*]}: install Debian's slurm-wlm and munge (scripts/setup.sh --deps)"
}

# A TCP port nobody listens on now (the kernel picks it; the small race with another
# program binding it before slurmctld does is acceptable for a test cluster).
free_port() {
  python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'
}

print_logs() {
  local dir=$1 f
  for f in "$dir"/log/*; do
    [ -f "$f" ] || continue
    echo "----- $f (last 60 lines) -----"
    tail -n 60 "$f"
  done
}

# Kill the daemon whose pid is in FILE (if it is still that daemon), wait for it to exit.
stop_pid() {
  local file=$1 name=$2 pid
  [ -f "$file" ] || return 0
  pid=$(cat "$file")
  [ -n "$pid" ] || return 0
  # Only signal the process if it is still the program we started (pids are reused).
  if [ -r "/proc/$pid/comm" ] && grep -q "^$name" "/proc/$pid/comm"; then
    kill -TERM "$pid" 2>/dev/null || true
    for _ in $(seq 1 50); do
      [ -e "/proc/$pid" ] || break
      sleep 0.2
    done
    if [ -e "/proc/$pid" ]; then
      echo "cluster.sh: $name (pid $pid) ignored SIGTERM for 10 s; sending SIGKILL" >&2
      kill -KILL "$pid" 2>/dev/null || true
    fi
  fi
  rm -f "$file"
}

start() {
  [ "$(id -u)" -eq 0 ] || die "must run as root (slurmd starts jobs as the submitting user)"
  need_tools
  local dir=${1:-}
  if [ -z "$dir" ]; then
    dir=$(mktemp -d "${TMPDIR:-/tmp}/heron-slurm.XXXXXX")
  else
    mkdir -p "$dir"
    [ -z "$(ls -A "$dir")" ] || die "$dir is not empty"
  fi
  dir=$(cd "$dir" && pwd -P)
  # The mark `stop` looks for before it removes a directory.
  : >"$dir/.heron-slurm-cluster"
  # Jobs run as root here, but the Slurm commands of any user must reach slurm.conf.
  chmod 0755 "$dir"
  mkdir -p "$dir/munge" "$dir/ctld" "$dir/spool" "$dir/log"
  # munged refuses a key or socket directory that others may write to, and wants the
  # socket's directory searchable by all (any user's sbatch talks to it).
  chmod 0755 "$dir/munge" "$dir/log"
  chmod 0700 "$dir/ctld" "$dir/spool"
  # Whatever fails from here on, stop what was started and remove DIR.
  STARTING_DIR=$dir
  trap 'abort_start' EXIT

  # A fresh key for this cluster only (mungekey writes 1024 random bits, mode 0600).
  mungekey --create --keyfile="$dir/munge/munge.key" ||
    die "mungekey could not create $dir/munge/munge.key"
  # munged daemonises after its checks; its failures go to stderr, kept in the log dir.
  munged --socket="$dir/munge/munge.socket.2" --key-file="$dir/munge/munge.key" \
    --pid-file="$dir/munge/munged.pid" --seed-file="$dir/munge/munged.seed" \
    --log-file="$dir/log/munged.log" --num-threads=2 \
    >"$dir/log/munged.out" 2>&1 || {
    cat "$dir/log/munged.out" >&2
    die "munged did not start (its message is above)"
  }
  cp "$dir/munge/munged.pid" "$dir/munged.pid"

  local host ctld_port slurmd_port cpus
  host=$(hostname -s)
  ctld_port=$(free_port)
  slurmd_port=$(free_port)
  while [ "$slurmd_port" = "$ctld_port" ]; do slurmd_port=$(free_port); done
  cpus=$(nproc)

  # The smallest configuration slurm 22.05 runs with: one node, one partition, no
  # accounting database (jobs are followed with squeue/scontrol; MinJobAge keeps finished
  # jobs visible to scontrol for 10 minutes), no cgroups. CR_CPU: CPUs are the only
  # consumable, so several array tasks share the node one CPU each. RealMemory is a floor
  # slurmd checks against the machine, kept small so any machine passes.
  # ReturnToService=2: the node becomes usable as soon as it registers.
  cat >"$dir/slurm.conf" <<EOF
# Written by tests/slurm/cluster.sh for a throw-away cluster in $dir
ClusterName=heron-test
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$dir/munge/munge.socket.2
StateSaveLocation=$dir/ctld
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SwitchType=switch/none
MpiDefault=none
MailProg=/bin/true
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
MinJobAge=600
SchedulerType=sched/backfill
NodeName=$host NodeAddr=127.0.0.1 NodeHostname=$host CPUs=$cpus RealMemory=100 State=UNKNOWN
PartitionName=debug Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
  export SLURM_CONF="$dir/slurm.conf"

  # -D: stay in the foreground, so this script holds the pid and their early errors
  # (before the log file opens) land in log/*.out; setsid detaches them from the caller's
  # terminal and process group. -i: ignore state from an earlier run (there is none).
  setsid slurmctld -D -i -f "$SLURM_CONF" >"$dir/log/slurmctld.out" 2>&1 </dev/null &
  echo $! >"$dir/slurmctld.daemon.pid"
  setsid slurmd -D -N "$host" -f "$SLURM_CONF" >"$dir/log/slurmd.out" 2>&1 </dev/null &
  echo $! >"$dir/slurmd.daemon.pid"

  local state=""
  for _ in $(seq 1 $((START_TIMEOUT * 2))); do
    for d in slurmctld slurmd; do
      if ! kill -0 "$(cat "$dir/$d.daemon.pid")" 2>/dev/null; then
        print_logs "$dir" >&2
        die "$d exited during start-up (logs above)"
      fi
    done
    state=$(sinfo --noheader --nodes="$host" --format=%T 2>/dev/null || true)
    case "$state" in
      idle) break ;;
      drain* | down* | fail*)
        # A node refused at registration (e.g. fewer CPUs than configured) says why.
        scontrol show node "$host" >&2 || true
        print_logs "$dir" >&2
        die "node $host is $state (details and logs above)"
        ;;
    esac
    sleep 0.5
  done
  if [ "$state" != idle ]; then
    print_logs "$dir" >&2
    die "node $host not idle after ${START_TIMEOUT} s (sinfo says '${state:-nothing}'; logs above)"
  fi
  trap - EXIT
  echo "export SLURM_CONF=$dir/slurm.conf"
  echo "export HERON_SLURM_DIR=$dir"
}

# EXIT trap while starting: a start that failed leaves no daemon and no directory behind.
STARTING_DIR=""
abort_start() {
  local status=$?
  if [ -n "$STARTING_DIR" ]; then
    stop "$STARTING_DIR" >/dev/null 2>&1 || true
  fi
  exit "$status"
}

stop() {
  local dir=${1:-}
  [ -n "$dir" ] || die "usage: cluster.sh stop DIR"
  [ -d "$dir" ] || return 0
  [ -f "$dir/.heron-slurm-cluster" ] || die "$dir was not made by cluster.sh start; not touching it"
  export SLURM_CONF="$dir/slurm.conf"
  # Cancel what is still queued or running, so no job step outlives slurmd.
  if [ -f "$dir/slurmctld.daemon.pid" ] && kill -0 "$(cat "$dir/slurmctld.daemon.pid")" 2>/dev/null; then
    scancel --full --quiet --user=root 2>/dev/null || true
    for _ in $(seq 1 $((STOP_TIMEOUT * 2))); do
      [ -z "$(squeue --noheader --format=%i --states=PD,R,CG,S 2>/dev/null)" ] && break
      sleep 0.5
    done
  fi
  stop_pid "$dir/slurmd.daemon.pid" slurmd
  stop_pid "$dir/slurmctld.daemon.pid" slurmctld
  stop_pid "$dir/munged.pid" munged
  rm -rf "$dir"
}

case "${1:-}" in
  start) start "${2:-}" ;;
  stop) stop "${2:-}" ;;
  logs) print_logs "${2:?usage: cluster.sh logs DIR}" ;;
  *) die "usage: cluster.sh start [DIR] | stop DIR | logs DIR" ;;
esac
