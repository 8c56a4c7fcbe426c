#!/usr/bin/env bash
# A one-node SLURM cluster on this host from Debian 12's packages, for the `slurm` nox session.
#   .ci/slurm_cluster.sh [start]   install (if needed), configure, start munged, mariadbd, slurmdbd,
#                                  slurmctld and slurmd, wait until the node is idle
#   .ci/slurm_cluster.sh stop      stop the daemons
# Runs as root; running it again leaves running daemons alone. No cgroups (containers): linuxproc tracking.
# Accounting (slurmdbd on MariaDB) is not optional: submitit learns that a task was cancelled or died
# only from sacct; without it the submitting process waits forever for that task's result.
set -euo pipefail

CONF=/etc/slurm/slurm.conf
DBD_CONF=/etc/slurm/slurmdbd.conf
MARK="# written by graspexp .ci/slurm_cluster.sh"
LOGS=/var/log/slurm
CTLD_PID=/run/slurmctld.pid
SLURMD_PID=/run/slurmd.pid
MUNGE_PID=/run/munge/munged.pid
DB_PID=/run/mysqld/mysqld.pid
DBD_PID=/run/slurmdbd.pid

running() { [[ -s $1 ]] && kill -0 "$(cat "$1")" 2>/dev/null; }

stop() {
    local pidfile pid
    for pidfile in "$SLURMD_PID" "$CTLD_PID" "$DBD_PID" "$DB_PID" "$MUNGE_PID"; do
        pid=$(cat "$pidfile" 2>/dev/null) || continue
        kill "$pid" 2>/dev/null || continue
        # by pid, not pid file: a daemon removes its file before it has finished shutting down
        for _ in $(seq 100); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    done
    echo "slurm_cluster: stopped"
}

install_packages() {
    local bin missing=""
    for bin in munged mariadbd slurmdbd slurmctld slurmd sbatch sacct; do
        command -v "$bin" >/dev/null || missing=1
    done
    [[ -z $missing ]] && return
    # keep the packages' init scripts from starting daemons before there is a config
    if [[ ! -e /usr/sbin/policy-rc.d ]]; then
        printf '#!/bin/sh\nexit 101\n' >/usr/sbin/policy-rc.d && chmod +x /usr/sbin/policy-rc.d
        trap 'rm -f /usr/sbin/policy-rc.d' EXIT
    fi
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
        munge mariadb-server slurmdbd slurmctld slurmd slurm-client >/dev/null
}

write_config() {
    local f
    for f in "$CONF" "$DBD_CONF"; do
        if [[ -e $f ]] && ! grep -qF "$MARK" "$f"; then
            echo "slurm_cluster: $f exists and is not ours; not overwriting it" >&2
            exit 1
        fi
    done
    local host node
    host=$(hostname -s)
    # "NodeName=<host> CPUs=.. Boards=.. SocketsPerBoard=.. CoresPerSocket=.. ThreadsPerCore=.. RealMemory=.."
    node=$(slurmd -C | head -n 1)
    mkdir -p /etc/slurm "$LOGS" /var/spool/slurmctld /var/spool/slurmd
    # KillWait: submitit's jobs ignore scancel's SIGTERM; SIGKILL comes this many seconds later (default 30)
    cat >"$CONF.new" <<EOF
$MARK
ClusterName=graspexp
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
AuthType=auth/munge
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/slurmdbd
AccountingStorageHost=localhost
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
KillWait=1
StateSaveLocation=/var/spool/slurmctld
SlurmdSpoolDir=/var/spool/slurmd
SlurmctldPidFile=$CTLD_PID
SlurmdPidFile=$SLURMD_PID
SlurmctldLogFile=$LOGS/slurmctld.log
SlurmdLogFile=$LOGS/slurmd.log
$node NodeAddr=127.0.0.1 State=UNKNOWN
PartitionName=debug Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
    mv "$CONF.new" "$CONF"
    # root reaches MariaDB through its unix socket (Debian's root@localhost uses unix_socket auth)
    (umask 077 && cat >"$DBD_CONF" <<EOF
$MARK
AuthType=auth/munge
DbdHost=localhost
SlurmUser=root
StorageType=accounting_storage/mysql
StorageUser=root
StorageLoc=slurm_acct_db
LogFile=$LOGS/slurmdbd.log
PidFile=$DBD_PID
EOF
    )
}

start_db() {
    running "$DB_PID" && return
    install -d -o mysql -g mysql -m 0755 /run/mysqld
    [[ -d /var/lib/mysql/mysql ]] || mariadb-install-db --user=mysql >/dev/null
    setsid runuser -u mysql -- mariadbd >"$LOGS/mariadb.log" 2>&1 </dev/null &
    for _ in $(seq 150); do mariadb-admin ping >/dev/null 2>&1 && return; sleep 0.2; done
    echo "slurm_cluster: MariaDB did not start; see $LOGS/mariadb.log" >&2
    exit 1
}

start_dbd() {
    running "$DBD_PID" || slurmdbd
    for _ in $(seq 150); do sacctmgr -n list cluster >/dev/null 2>&1 && break; sleep 0.2; done
    sacctmgr -n -P list cluster format=cluster | grep -qx graspexp || sacctmgr -i add cluster graspexp >/dev/null
}

start_munge() {
    running "$MUNGE_PID" && return
    [[ -s /etc/munge/munge.key ]] || mungekey --create --keyfile=/etc/munge/munge.key
    chown munge:munge /etc/munge/munge.key && chmod 0400 /etc/munge/munge.key
    install -d -o munge -g munge -m 0755 /run/munge
    install -d -o munge -g munge -m 0700 /var/lib/munge /var/log/munge
    runuser -u munge -- munged
}

start() {
    install_packages
    write_config
    start_munge
    start_db
    start_dbd
    if running "$CTLD_PID"; then
        scontrol reconfigure  # a config written by a newer version of this script
    else
        slurmctld
    fi
    running "$SLURMD_PID" || slurmd
    local host state
    host=$(hostname -s)
    for _ in $(seq 150); do
        state=$(sinfo -h -n "$host" -o %T 2>/dev/null || true)
        if [[ $state == idle* || $state == mixed* || $state == allocated* ]]; then
            echo "slurm_cluster: node $host $state"
            return
        fi
        sleep 0.2
    done
    echo "slurm_cluster: node $host not up (state '${state:-?}'); see $LOGS/" >&2
    tail -n 20 "$LOGS/slurmctld.log" "$LOGS/slurmd.log" >&2 || true
    exit 1
}

case "${1:-start}" in
    start) start ;;
    stop) stop ;;
    *) echo "usage: $0 [start|stop]" >&2; exit 2 ;;
esac
