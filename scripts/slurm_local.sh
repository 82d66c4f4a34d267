#!/usr/bin/env bash
# A one-node Slurm cluster on this machine, for testing `clothsim study ... --executor slurm`
# (docs/cluster.md). Debian 12, as root, without systemd or cgroups.
#
# Usage: scripts/slurm_local.sh start|stop|status
#   start   installs slurmctld, slurmd, slurm-client and munge if missing (Debian packages; their
#           services are kept from starting during the install), writes a minimal configuration
#           to $CLOTHSIM_SLURM_DIR (default /run/clothsim-slurm), starts munged (unless one is
#           running), slurmctld and slurmd, and waits until the node is idle. Clients find the
#           configuration through /etc/slurm/slurm.conf (a link made here if that file does not
#           exist) or `export SLURM_CONF=$CLOTHSIM_SLURM_DIR/slurm.conf`.
#   stop    stops the daemons `start` started, by the PIDs it recorded, and removes the link.
#   status  prints the node's state (sinfo).
# Configuration: proctrack/linuxproc and task/none (no cgroups), no accounting database
# (jobcomp/filetxt writes one line per finished task to $CLOTHSIM_SLURM_DIR/jobcomp.txt),
# batch_sched_delay=0 (array tasks start as soon as a CPU is free), the controller and the node on
# 127.0.0.1 (ports 6817, 6818), one partition "debug" with every CPU of this machine.
set -euo pipefail

dir="${CLOTHSIM_SLURM_DIR:-/run/clothsim-slurm}"
conf="$dir/slurm.conf"
etc_conf=/etc/slurm/slurm.conf

die() { echo "slurm_local: error: $*" >&2; exit 1; }

alive() { [ -s "$1" ] && kill -0 "$(cat "$1")" 2>/dev/null; }

install_packages() {
  local missing=()
  for p in slurmctld slurmd slurm-client munge; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  echo "slurm_local: installing ${missing[*]}"
  # Keep the packages' services from starting (they would run without this configuration).
  local policy=/usr/sbin/policy-rc.d made_policy=0
  if [ ! -e "$policy" ]; then
    printf '#!/bin/sh\nexit 101\n' > "$policy"
    chmod 755 "$policy"
    made_policy=1
  fi
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null ||
    { [ $made_policy = 1 ] && rm -f "$policy"; die "apt-get install ${missing[*]} failed"; }
  [ $made_policy = 1 ] && rm -f "$policy"
  return 0
}

start() {
  [ "$(id -u)" -eq 0 ] || die "start needs root (it installs packages and runs the daemons as root)"
  if alive "$dir/slurmctld.pid" || alive "$dir/slurmd.pid"; then
    echo "slurm_local: already running (PID files in $dir); scripts/slurm_local.sh stop first" >&2
    exit 1
  fi
  local t0=$SECONDS
  install_packages
  mkdir -p "$dir/state" "$dir/spool"
  local host node
  host=$(hostname -s)
  # The node line as slurmd sees this machine (CPUs, sockets, cores, threads, memory).
  node=$(slurmd -C | grep '^NodeName=' | sed 's/ UpTime=.*//')
  [ -n "$node" ] || die "slurmd -C printed no node line"
  cat > "$conf" <<EOF
# Written by scripts/slurm_local.sh: a one-node test cluster without cgroups or accounting.
ClusterName=clothsim
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
SlurmctldPort=6817
SlurmdPort=6818
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
MpiDefault=none
MailProg=/bin/true
ReturnToService=2
SchedulerType=sched/backfill
SchedulerParameters=batch_sched_delay=0
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
JobCompType=jobcomp/filetxt
JobCompLoc=$dir/jobcomp.txt
$node NodeAddr=127.0.0.1 State=UNKNOWN
PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
  if [ ! -e "$etc_conf" ]; then
    mkdir -p "$(dirname "$etc_conf")"
    ln -s "$conf" "$etc_conf"
    echo "$etc_conf" > "$dir/linked_conf"
  elif [ "$(readlink -f "$etc_conf")" != "$(readlink -f "$conf")" ]; then
    echo "slurm_local: note: $etc_conf exists and is not this cluster's; clients need SLURM_CONF=$conf" >&2
  fi
  export SLURM_CONF="$conf"

  # munge: /run/munge does not exist without systemd.
  mkdir -p /run/munge
  chown munge:munge /run/munge
  chmod 0755 /run/munge
  if pgrep -x munged >/dev/null; then
    echo "slurm_local: munged is running already (not started here)"
  else
    runuser -u munge -- /usr/sbin/munged
    local i
    for i in $(seq 50); do [ -s /run/munge/munged.pid ] && break; sleep 0.1; done
    [ -s /run/munge/munged.pid ] || die "munged did not start"
    cp /run/munge/munged.pid "$dir/munged.pid"
  fi
  munge -n | unmunge >/dev/null || die "munge does not work (munge -n | unmunge)"

  # -i: ignore (missing) state files on the first start.
  slurmctld -i -f "$conf" || die "slurmctld did not start (log: $dir/slurmctld.log)"
  slurmd -f "$conf" || die "slurmd did not start (log: $dir/slurmd.log)"
  local state=""
  for i in $(seq 300); do
    state=$(sinfo -h -N -o %T 2>/dev/null | head -1 || true)
    [ "$state" = idle ] && break
    sleep 0.2
  done
  [ "$state" = idle ] || die "the node is not idle after 60 s (state '$state'; logs in $dir)"
  echo "slurm_local: one-node cluster up in $((SECONDS - t0)) s: node $host ($(sinfo -h -N -o '%c CPUs')), partition debug; configuration $conf"
}

stop() {
  local name stopped=0
  for name in slurmd slurmctld munged; do
    local pidfile="$dir/$name.pid"
    [ -s "$pidfile" ] || continue
    local pid
    pid=$(cat "$pidfile")
    if kill -0 "$pid" 2>/dev/null; then
      kill "$pid"
      for _ in $(seq 100); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
      kill -0 "$pid" 2>/dev/null && kill -9 "$pid"
      stopped=$((stopped + 1))
    fi
    rm -f "$pidfile"
  done
  if [ -s "$dir/linked_conf" ]; then
    local link
    link=$(cat "$dir/linked_conf")
    [ -L "$link" ] && rm -f "$link"
    rm -f "$dir/linked_conf"
  fi
  echo "slurm_local: stopped $stopped daemons"
}

case "${1:-}" in
  start) start ;;
  stop) stop ;;
  status) SLURM_CONF="$conf" sinfo -N ;;
  *) echo "usage: scripts/slurm_local.sh start|stop|status" >&2; exit 2 ;;
esac
