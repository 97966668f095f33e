#!/bin/sh
# A real two-node Slurm cluster on the loopback interface, without systemd,
# for `partray farm --engine slurm` tests and trials:
#
#   scripts/slurm_local.sh start DIR [NODES]   # munged, slurmctld, NODES slurmd (default 2)
#   scripts/slurm_local.sh stop DIR            # stops every daemon it started, by PID
#   . DIR/env                                  # SLURM_CONF for sbatch, squeue, scancel
#
# Everything lives in DIR: munge key and socket, slurm.conf, state, spool,
# logs and PID files. Debian 12's Slurm 22.05 runs this way inside a
# container: munged --force with its socket in DIR, slurmctld -f CONF and
# one `slurmd -N NAME` per node on 127.0.0.1, each node with its own port,
# spool, PID and log (slurm.conf(5): NodeName ... Port=, SlurmdSpoolDir and
# SlurmdPidFile with %n), ProctrackType=proctrack/linuxproc and
# TaskPlugin=task/none (no cgroups here), SlurmUser=root. Each node offers
# one CPU, so two nodes run two tasks at once. Ports are chosen from free
# ones so two clusters (two test runs) do not meet.
set -eu
cmd=${1:-}
dir=${2:-}
[ -n "$cmd" ] && [ -n "$dir" ] || { echo "usage: $0 start|stop DIR [NODES]" >&2; exit 2; }

free_port() {
    python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1]); s.close()'
}

stop() {
    # slurmd first, then the controller, then munge; each by the PID it wrote
    for f in "$dir"/slurmd.*.pid "$dir/slurmctld.pid" "$dir/munged.pid"; do
        [ -f "$f" ] || continue
        pid=$(cat "$f" 2>/dev/null || true)
        if [ -n "$pid" ] && kill -0 "$pid" 2>/dev/null; then
            kill "$pid" 2>/dev/null || true
            i=0
            while kill -0 "$pid" 2>/dev/null && [ $i -lt 50 ]; do sleep 0.1; i=$((i + 1)); done
            if kill -0 "$pid" 2>/dev/null; then kill -9 "$pid" 2>/dev/null || true; fi
        fi
        rm -f "$f"
    done
}

case "$cmd" in
stop)
    stop
    exit 0
    ;;
start) ;;
*) echo "usage: $0 start|stop DIR [NODES]" >&2; exit 2 ;;
esac

nodes=${3:-2}
for b in munged slurmctld slurmd sbatch; do
    command -v "$b" >/dev/null 2>&1 || [ -x "/usr/sbin/$b" ] || { echo "slurm_local: $b missing (scripts/setup.sh installs slurmctld slurmd slurm-client munge)" >&2; exit 3; }
done
PATH="$PATH:/usr/sbin"
mkdir -p "$dir"
dir=$(cd "$dir" && pwd)
mkdir -p "$dir/state" "$dir/spool"
chmod 700 "$dir"

# munge: a fresh key, its socket and files in DIR
dd if=/dev/urandom of="$dir/munge.key" bs=1024 count=1 2>/dev/null
chmod 400 "$dir/munge.key"
munged --force --socket="$dir/munge.sock" --key-file="$dir/munge.key" --pid-file="$dir/munged.pid" \
    --log-file="$dir/munged.log" --seed-file="$dir/munged.seed"

ctld_port=$(free_port)
host=$(hostname)
{
    echo "ClusterName=partray"
    echo "SlurmctldHost=$host(127.0.0.1)"
    echo "SlurmctldPort=$ctld_port"
    echo "SlurmUser=root"
    echo "SlurmdUser=root"
    echo "AuthType=auth/munge"
    echo "AuthInfo=socket=$dir/munge.sock"
    echo "CredType=cred/munge"
    echo "StateSaveLocation=$dir/state"
    echo "SlurmdSpoolDir=$dir/spool/%n"
    echo "SlurmctldPidFile=$dir/slurmctld.pid"
    echo "SlurmdPidFile=$dir/slurmd.%n.pid"
    echo "SlurmctldLogFile=$dir/slurmctld.log"
    echo "SlurmdLogFile=$dir/slurmd.%n.log"
    echo "ProctrackType=proctrack/linuxproc"
    echo "TaskPlugin=task/none"
    echo "SchedulerType=sched/backfill"
    echo "SelectType=select/cons_tres"
    echo "SelectTypeParameters=CR_CPU"
    echo "ReturnToService=2"
    echo "MpiDefault=none"
    echo "JobCompType=jobcomp/none"
    echo "AccountingStorageType=accounting_storage/none"
    echo "JobAcctGatherType=jobacct_gather/none"
    echo "SlurmctldTimeout=30"
    echo "SlurmdTimeout=30"
    echo "InactiveLimit=0"
    echo "MinJobAge=300"
    echo "KillWait=5"
    echo "Waittime=0"
    names=""
    i=1
    while [ $i -le "$nodes" ]; do
        echo "NodeName=n$i NodeHostname=$host NodeAddr=127.0.0.1 Port=$(free_port) CPUs=1 RealMemory=1000 State=UNKNOWN"
        names="$names${names:+,}n$i"
        i=$((i + 1))
    done
    echo "PartitionName=farm Nodes=$names Default=YES MaxTime=INFINITE State=UP"
} >"$dir/slurm.conf"
echo "export SLURM_CONF='$dir/slurm.conf'" >"$dir/env"
export SLURM_CONF="$dir/slurm.conf"

slurmctld -f "$dir/slurm.conf"
i=1
while [ $i -le "$nodes" ]; do
    mkdir -p "$dir/spool/n$i"
    slurmd -f "$dir/slurm.conf" -N "n$i"
    i=$((i + 1))
done

# ready when every node is idle
t=0
while :; do
    idle=$(sinfo -h -o '%T %D' 2>/dev/null | awk '$1 == "idle" { n += $2 } END { print n + 0 }')
    [ "$idle" -ge "$nodes" ] && break
    t=$((t + 1))
    if [ $t -gt 150 ]; then
        echo "slurm_local: nodes not idle after 30 s; logs in $dir" >&2
        sinfo >&2 || true
        stop
        exit 1
    fi
    sleep 0.2
done
echo "slurm_local: $nodes nodes up in $dir (. $dir/env)"
