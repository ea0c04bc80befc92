#!/usr/bin/env bash
# A private one-node Slurm (slurmctld, slurmd and munge from Debian's slurm-wlm, no systemd, no cgroups) in a
# folder of its own, for the cluster tests and for trying `surge run --slurm` on one machine.
#   source scripts/slurm_local.sh
#   slurm_local_start FOLDER    # starts munged, slurmctld and slurmd; exports SLURM_CONF; waits for an idle node
#   slurm_local_stop FOLDER     # stops them (slurmd, slurmctld, munged; KILL after a few seconds) and leaves none
# Needs root (the daemons run as root here) and the packages slurm-wlm and munge (scripts/setup.sh installs them).
# Ports 26817/26818 by default (SURGE_SLURM_PORT_BASE changes them), so that a site's own Slurm is not disturbed.

slurm_local_start() {
  local dir="$1"
  local port="${SURGE_SLURM_PORT_BASE:-26817}"
  mkdir -p "$dir"/{munge,munge-socket,state,spool,log}
  dir="$(cd "$dir" && pwd)"
  chmod 700 "$dir/munge"
  chmod 755 "$dir/munge-socket"
  head -c 1024 /dev/urandom >"$dir/munge/munge.key"
  chmod 400 "$dir/munge/munge.key"
  munged --socket="$dir/munge-socket/munge.socket" --key-file="$dir/munge/munge.key" \
    --pid-file="$dir/munge/munged.pid" --log-file="$dir/log/munged.log" --seed-file="$dir/munge/munged.seed" \
    --origin=127.0.0.1 --force || return 1

  local cpus memory
  cpus="$(nproc)"
  memory="$(awk '/MemTotal/ {print int($2 / 1024 * 0.9)}' /proc/meminfo)"
  cat >"$dir/slurm.conf" <<EOF
ClusterName=surgelocal
SlurmctldHost=localhost(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$dir/munge-socket/munge.socket
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
SchedulerParameters=batch_sched_delay=0
MpiDefault=none
KillWait=10
MinJobAge=600
NodeName=localhost NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$memory State=UNKNOWN
PartitionName=debug Nodes=localhost Default=YES MaxTime=INFINITE State=UP
EOF
  export SLURM_CONF="$dir/slurm.conf"
  slurmctld -f "$SLURM_CONF" || return 1
  slurmd -N localhost -f "$SLURM_CONF" || return 1  # the node by name, not by resolving the machine's
  local i
  for i in $(seq 1 100); do
    if sinfo -h -o '%t' 2>/dev/null | grep -q '^idle'; then return 0; fi
    sleep 0.2
  done
  echo "slurm_local: the node did not come up idle; logs in $dir/log" >&2
  return 1
}

# Stops a daemon by the pid in its file: TERM, then KILL after a few seconds.
slurm_local_kill() {
  local file="$1" pid i
  [ -f "$file" ] || return 0
  pid="$(cat "$file")"
  [ -n "$pid" ] && kill -0 "$pid" 2>/dev/null || return 0
  kill "$pid" 2>/dev/null
  for i in $(seq 1 30); do
    kill -0 "$pid" 2>/dev/null || return 0
    sleep 0.2
  done
  kill -9 "$pid" 2>/dev/null
  sleep 0.2
}

slurm_local_stop() {
  local dir="$1"
  [ -d "$dir" ] || return 0
  # slurmd first: with slurmctld gone first it ignores TERM for minutes.
  slurm_local_kill "$dir/slurmd.pid"
  slurm_local_kill "$dir/slurmctld.pid"
  slurm_local_kill "$dir/munge/munged.pid"
  # A job step still running (a killed test) goes too: its processes are children of slurmstepd.
  pkill -9 -f "slurmstepd.*$dir" 2>/dev/null || true
  unset SLURM_CONF
}
