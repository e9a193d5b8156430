#!/usr/bin/env bash
# A one-machine Slurm cluster for drapelab's Slurm tests (issue 18): installs Debian's slurm-wlm and
# munge when absent (apt-get update first; needs root and Debian's package mirrors), writes a
# single-node slurm.conf (this host, its CPU count, cons_tres), starts munged, slurmctld and slurmd in
# the background on this machine only, and waits until `sinfo` shows the node idle. Idempotent: a
# cluster already up (e.g. from an earlier test run) is left as it is; daemons that died are
# restarted. Prints nothing on success but the last line "slurm up: NODE, N CPUs".
set -euo pipefail

log=/tmp/drapelab-slurm-up.log
if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null || ! command -v sbatch >/dev/null; then
  export DEBIAN_FRONTEND=noninteractive
  { apt-get update && apt-get install -y --no-install-recommends slurm-wlm munge; } >>"$log" 2>&1 || {
    echo "up.sh: could not install slurm-wlm and munge with apt (see $log)" >&2
    exit 1
  }
fi

node=$(hostname -s)
cpus=$(nproc)
# Memory for the node: what the machine has, less 1 GiB.
mem=$(awk '/MemTotal/ { printf "%d", $2 / 1024 - 1024 }' /proc/meminfo)
conf=/etc/slurm/slurm.conf
want=$(cat <<EOF
# Written by drapelab's tests/slurm/up.sh: a one-machine cluster.
ClusterName=drapelab
SlurmctldHost=$node
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
StateSaveLocation=/var/spool/slurmctld
SlurmdSpoolDir=/var/spool/slurmd
SlurmctldPidFile=/run/slurmctld.pid
SlurmdPidFile=/run/slurmd.pid
SlurmctldLogFile=/var/log/slurm/slurmctld.log
SlurmdLogFile=/var/log/slurm/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MinJobAge=30
SlurmdTimeout=60
MpiDefault=none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
NodeName=$node CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=debug Nodes=$node Default=YES MaxTime=INFINITE State=UP OverSubscribe=NO
EOF
)
mkdir -p /etc/slurm /var/spool/slurmctld /var/spool/slurmd /var/log/slurm /run/munge
if [ "$(cat "$conf" 2>/dev/null)" != "$want" ]; then
  printf '%s\n' "$want" >"$conf"
  pkill -x slurmctld 2>/dev/null || true
  pkill -x slurmd 2>/dev/null || true
  sleep 1
fi

if [ ! -s /etc/munge/munge.key ]; then
  mkdir -p /etc/munge
  dd if=/dev/urandom of=/etc/munge/munge.key bs=1024 count=1 2>/dev/null
fi
chown -R munge:munge /etc/munge /run/munge /var/lib/munge /var/log/munge 2>/dev/null || true
chmod 0400 /etc/munge/munge.key
pgrep -x munged >/dev/null || runuser -u munge -- /usr/sbin/munged >>"$log" 2>&1 ||
  /usr/sbin/munged --force >>"$log" 2>&1
pgrep -x slurmctld >/dev/null || slurmctld >>"$log" 2>&1
pgrep -x slurmd >/dev/null || slurmd >>"$log" 2>&1

# Wait for the node to be idle (or mixed/allocated by jobs of an earlier run) for up to 60 s.
for _ in $(seq 1 60); do
  state=$(sinfo -h -n "$node" -o %T 2>/dev/null | head -1 || true)
  case "$state" in
    idle* | mixed* | allocated*)
      echo "slurm up: $node, $cpus CPUs"
      exit 0
      ;;
    down* | drain*)
      scontrol update nodename="$node" state=resume >>"$log" 2>&1 || true
      ;;
  esac
  sleep 1
done
echo "up.sh: the Slurm node $node is not idle after 60 s (sinfo: ${state:-nothing}; logs in /var/log/slurm and $log)" >&2
exit 1
