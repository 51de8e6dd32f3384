#!/usr/bin/env bash
# A real single-node SLURM cluster on this machine, from Debian's packages (root needed).
#   tests/slurm/cluster.sh up     install what is missing, write /etc/slurm/slurm.conf, start
#                                 munged, slurmctld and slurmd, wait until the node is idle
#   tests/slurm/cluster.sh down   stop the daemons this script started
# Facts it rests on: SLURM 22.05 from bookworm; no systemd, so the daemons run
# as background processes; the config must be at /etc/slurm/slurm.conf (the executor's job step
# does not pass SLURM_CONF on); no accounting database, so job status comes from squeue.
set -euo pipefail

STATE=/run/ballbat-slurm
mkdir -p "$STATE"

up() {
    if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null || ! command -v munged >/dev/null; then
        apt-get update -qq
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq slurmctld slurmd slurm-client munge >/dev/null
    fi
    local host cpus mem
    host=$(hostname -s)
    cpus=$(slurmd -C | sed -n 's/.*CPUs=\([0-9]*\).*/\1/p' | head -n1)
    mem=$(slurmd -C | sed -n 's/.*RealMemory=\([0-9]*\).*/\1/p' | head -n1)
    mkdir -p /etc/slurm /var/spool/slurmctld /var/spool/slurmd /var/log/slurm /run/munge /var/lib/munge /var/log/munge
    cat >/etc/slurm/slurm.conf <<EOF
ClusterName=ballbat
SlurmctldHost=${host}
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
SchedulerType=sched/backfill
StateSaveLocation=/var/spool/slurmctld
SlurmdSpoolDir=/var/spool/slurmd
SlurmctldPidFile=${STATE}/slurmctld.pid
SlurmdPidFile=${STATE}/slurmd.pid
SlurmctldLogFile=/var/log/slurm/slurmctld.log
SlurmdLogFile=/var/log/slurm/slurmd.log
ReturnToService=2
MpiDefault=none
NodeName=${host} CPUs=${cpus} RealMemory=${mem} State=UNKNOWN
PartitionName=main Nodes=${host} Default=YES MaxTime=INFINITE State=UP
EOF
    if [ ! -s /etc/munge/munge.key ]; then
        if command -v mungekey >/dev/null; then mungekey --create --force >/dev/null 2>&1 || true; fi
        [ -s /etc/munge/munge.key ] || /usr/sbin/create-munge-key -f >/dev/null 2>&1 || true
    fi
    chown -R munge:munge /etc/munge /run/munge /var/lib/munge /var/log/munge 2>/dev/null || true
    chmod 0700 /etc/munge 2>/dev/null || true
    chmod 0400 /etc/munge/munge.key 2>/dev/null || true
    if [ ! -S /run/munge/munge.socket.2 ]; then
        runuser -u munge -- /usr/sbin/munged --force
        echo started >"$STATE/munged"
        for _ in $(seq 1 20); do
            [ -S /run/munge/munge.socket.2 ] && break
            sleep 0.25
        done
    fi
    munge -n | unmunge >/dev/null || { echo "slurm: munge does not work" >&2; return 1; }
    /usr/sbin/slurmctld -D >>/var/log/slurm/slurmctld.out 2>&1 &
    echo $! >"$STATE/slurmctld.bg"
    sleep 1
    /usr/sbin/slurmd -D >>/var/log/slurm/slurmd.out 2>&1 &
    echo $! >"$STATE/slurmd.bg"
    for _ in $(seq 1 60); do
        state=$(sinfo -h -o %T 2>/dev/null | head -n1 || true)
        if [ "$state" = "idle" ] || [ "$state" = "mixed" ]; then
            echo "slurm: node ${host} ${state} (${cpus} CPUs, ${mem} MB)"
            return 0
        fi
        scontrol update nodename="${host}" state=resume >/dev/null 2>&1 || true
        sleep 1
    done
    echo "slurm: node did not become idle; see /var/log/slurm/" >&2
    tail -n 20 /var/log/slurm/slurmctld.log /var/log/slurm/slurmd.log >&2 || true
    return 1
}

down() {
    for d in slurmd slurmctld; do
        if [ -f "$STATE/$d.bg" ]; then
            pid=$(cat "$STATE/$d.bg")
            kill "$pid" 2>/dev/null || true
            for _ in $(seq 1 20); do kill -0 "$pid" 2>/dev/null || break; sleep 0.25; done
            kill -9 "$pid" 2>/dev/null || true
            rm -f "$STATE/$d.bg"
        fi
    done
    if [ -f "$STATE/munged" ]; then
        [ -f /run/munge/munged.pid ] && kill "$(cat /run/munge/munged.pid)" 2>/dev/null || true
        rm -f "$STATE/munged"
    fi
}

case "${1:-}" in
up) up ;;
down) down ;;
*)
    echo "usage: $0 up|down" >&2
    exit 2
    ;;
esac
