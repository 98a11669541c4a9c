#!/usr/bin/env bash
# slurm_local.sh — throw-away single-node Slurm cluster on localhost (for tests).
#
#   slurm_local.sh start DIR   # create config/key/dirs under DIR, start munged,
#                              # slurmctld, slurmd; wait until the node is idle
#   slurm_local.sh stop  DIR   # kill the daemons via their pid files; keep DIR
#
# After `start`:  export SLURM_CONF=DIR/slurm.conf   (sbatch/squeue/sinfo/scancel)
# Tested with Debian 12 slurm-wlm 22.05.8 + munge 0.5.15, run as root, no systemd.
set -euo pipefail

die() { echo "slurm_local: $*" >&2; exit 1; }
log() { echo "slurm_local: $*" >&2; }

usage() { echo "usage: $0 {start|stop} DIR" >&2; exit 2; }
[ $# -eq 2 ] || usage
CMD=$1
[ "$CMD" = start ] && mkdir -p "$2"
[ -d "$2" ] || die "no such directory: $2"
DIR=$(cd "$2" && pwd -P)          # absolute path: slurm.conf needs absolute paths

# ---- binaries (overridable via env) ------------------------------------------
MUNGED=${MUNGED:-$(command -v munged || echo /usr/sbin/munged)}
MUNGE=${MUNGE:-$(command -v munge || echo /usr/bin/munge)}
UNMUNGE=${UNMUNGE:-$(command -v unmunge || echo /usr/bin/unmunge)}
SLURMCTLD=${SLURMCTLD:-$(command -v slurmctld || echo /usr/sbin/slurmctld)}
SLURMD=${SLURMD:-$(command -v slurmd || echo /usr/sbin/slurmd)}
SINFO=${SINFO:-$(command -v sinfo || echo /usr/bin/sinfo)}
SLURM_LOCAL_TIMEOUT=${SLURM_LOCAL_TIMEOUT:-60}

MUNGE_SOCK=$DIR/munge/munge.socket
case "$DIR" in *[[:space:]]*|*'#'*) die "DIR must not contain whitespace or '#' (slurm.conf): $DIR" ;; esac
# AF_UNIX paths are limited to 108 bytes (munge socket, slurmd's spool socket).
[ ${#DIR} -le 80 ] || die "DIR path too long for unix sockets (${#DIR} > 80 chars): $DIR"
CONF=$DIR/slurm.conf

# ---- helpers ------------------------------------------------------------------
# Is TCP port $1 in use (any state) on this host? Reads /proc/net/tcp{,6}.
port_in_use() {
    local hex; hex=$(printf '%04X' "$1")
    cat /proc/net/tcp /proc/net/tcp6 2>/dev/null |
        awk -v p=":$hex" 'NR>1 && (substr($2, length($2)-4) == p) {f=1} END {exit !f}'
}
# Print a free port in [20000, 60000) that is not in "$@".
pick_port() {
    local p i x ok
    for i in $(seq 1 200); do
        p=$(( 20000 + (RANDOM * 32768 + RANDOM) % 40000 ))
        ok=1
        for x in "$@"; do [ "$x" = "$p" ] && ok=0; done
        [ $ok = 1 ] && ! port_in_use "$p" && { echo "$p"; return 0; }
    done
    die "could not find a free TCP port"
}
descendants() {   # all (transitive) child pids of $1
    ps -eo pid=,ppid= | awk -v root="$1" '
        { kids[$2] = kids[$2] " " $1 }
        END { n = split(kids[root], q, " "); i = 1
              while (i <= n) { p = q[i++]; printf "%s ", p
                               m = split(kids[p], c, " "); for (j = 1; j <= m; j++) q[++n] = c[j] } }'
}
pid_alive() { [ -n "${1:-}" ] && kill -0 "$1" 2>/dev/null; }
read_pid() { [ -s "$1" ] && tr -dc '0-9' <"$1" || true; }

dump_logs() {
    local f
    for f in "$DIR"/log/munged.log "$DIR"/log/slurmctld.log "$DIR"/log/slurmd.log \
             "$DIR"/log/*.out; do
        [ -f "$f" ] || continue
        echo "===== $f (last 60 lines) =====" >&2
        tail -n 60 "$f" >&2 || true
    done
}

# stop_pids NAME:PIDFILE... — SIGTERM all at once (each daemon needs ~2 s to
# exit, in parallel that is ~2 s total), SIGKILL whatever is left after 15 s.
stop_pids() {
    local spec name pf pid i names=() pids=() left
    for spec in "$@"; do
        name=${spec%%:*}; pf=${spec#*:}
        pid=$(read_pid "$pf")
        pid_alive "$pid" || continue
        # guard against pid reuse: the daemon's command line names DIR
        tr '\0' ' ' <"/proc/$pid/cmdline" 2>/dev/null | grep -qF "$DIR/" \
            || { log "pid $pid from $pf is not our $name; not killing it"; continue; }
        kill -TERM "$pid" 2>/dev/null || true
        names+=("$name"); pids+=("$pid")
    done
    for i in $(seq 1 150); do
        left=0
        for pid in "${pids[@]}"; do pid_alive "$pid" && left=1; done
        [ $left = 0 ] && break
        sleep 0.1
    done
    for i in "${!pids[@]}"; do
        if pid_alive "${pids[$i]}"; then
            log "${names[$i]} (pid ${pids[$i]}) ignored SIGTERM for 15s, sending SIGKILL"
            kill -KILL "${pids[$i]}" 2>/dev/null || true
        else
            log "stopped ${names[$i]} (pid ${pids[$i]})"
        fi
    done
}

do_stop() {
    [ -f "$CONF" ] || { log "no $CONF; nothing to stop"; return 0; }
    # Cancel whatever is still queued/running so no slurmstepd/job survives.
    if [ -f "$DIR/pid/slurmctld.pid" ] && pid_alive "$(read_pid "$DIR/pid/slurmctld.pid")"; then
        local jobs
        jobs=$(SLURM_CONF=$CONF timeout 10 squeue -h -o %i 2>/dev/null || true)
        if [ -n "$jobs" ]; then
            # shellcheck disable=SC2086
            SLURM_CONF=$CONF timeout 10 scancel $jobs 2>/dev/null || true
            sleep 1
        fi
    fi
    stop_pids slurmd:"$DIR/pid/slurmd.pid" slurmctld:"$DIR/pid/slurmctld.pid" \
              munged:"$DIR/pid/munged.pid"
    # Kill leftover slurmstepd processes of THIS instance only (they inherit
    # SLURM_CONF=DIR/slurm.conf from slurmd's environment) plus their job
    # processes. Normally nothing is left because of the scancel above.
    local p victims=""
    for p in $(pgrep -x slurmstepd 2>/dev/null || true); do
        if tr '\0' '\n' <"/proc/$p/environ" 2>/dev/null | grep -qxF "SLURM_CONF=$CONF"; then
            victims="$victims $p $(descendants "$p")"
        fi
    done
    if [ -n "${victims// /}" ]; then
        log "killing leftover job processes:$victims"
        # shellcheck disable=SC2086
        kill -KILL $victims 2>/dev/null || true
    fi
}

do_start() {
    local f
    for f in "$MUNGED" "$MUNGE" "$UNMUNGE" "$SLURMCTLD" "$SLURMD" "$SINFO"; do
        [ -x "$f" ] || die "missing executable: $f"
    done
    # Non-root works too (daemons run as the caller, SlurmUser=SlurmdUser=caller),
    # but only jobs of that same user can run; see NOTES.md.
    [ "$(id -u)" = 0 ] || log "note: not root; daemons run as $(id -un), only its jobs can run"
    if [ -f "$DIR/pid/slurmctld.pid" ] && pid_alive "$(read_pid "$DIR/pid/slurmctld.pid")"; then
        die "a cluster is already running in $DIR (run: $0 stop $DIR)"
    fi

    local t0=$SECONDS
    local host; host=$(hostname -s 2>/dev/null || hostname)
    [ -n "$host" ] || die "cannot determine hostname"
    local user; user=$(id -un)

    # munged checks: socket dir (and all its parents) must be o+x and not
    # group/other-writable (sticky /tmp is OK); key/seed dir must be private.
    # So DIR becomes 0755 even if the caller made it with `mktemp -d` (0700).
    mkdir -p "$DIR"/{munge,munge-key,etc,state,spool,log,pid,jobs}
    chmod 0755 "$DIR" "$DIR/munge" "$DIR/log" "$DIR/etc"
    chmod 0700 "$DIR/munge-key" "$DIR/state" "$DIR/spool" "$DIR/pid"
    chmod 1777 "$DIR/jobs"   # scratch dir for job output

    # ---- munge key + munged ----------------------------------------------------
    local key=$DIR/munge-key/munge.key
    if [ ! -s "$key" ]; then
        ( umask 077; dd if=/dev/urandom of="$key" bs=1024 count=1 status=none )
    fi
    chmod 0400 "$key"
    "$MUNGED" --socket="$MUNGE_SOCK" --key-file="$key" \
              --log-file="$DIR/log/munged.log" --pid-file="$DIR/pid/munged.pid" \
              --seed-file="$DIR/munge-key/munged.seed" --num-threads=4 \
              --origin=127.0.0.1 \
        || { dump_logs; die "munged failed to start"; }
    local i ok=0
    for i in $(seq 1 50); do
        if "$MUNGE" -S "$MUNGE_SOCK" -n 2>/dev/null | "$UNMUNGE" -S "$MUNGE_SOCK" >/dev/null 2>&1; then ok=1; break; fi
        sleep 0.1
    done
    [ $ok = 1 ] || { dump_logs; do_stop; die "munged not answering on $MUNGE_SOCK"; }

    # ---- node hardware: take it from `slurmd -C` so it matches what slurmd
    #      will report at registration (otherwise the node gets drained). ----
    local hw cpus boards spb cps tpc memtot mem
    hw=$("$SLURMD" -C 2>/dev/null | head -n1 || true)
    field() { sed -n "s/.*[[:space:]]$1=\([0-9]*\).*/\1/p" <<<"$hw"; }
    cpus=$(field CPUs); boards=$(field Boards); spb=$(field SocketsPerBoard)
    cps=$(field CoresPerSocket); tpc=$(field ThreadsPerCore)
    memtot=$(awk '/^MemTotal:/ {print int($2/1024)}' /proc/meminfo)
    mem=$(( memtot * 95 / 100 )); [ "$mem" -ge 1 ] || mem=1
    local nodehw
    if [ -n "$cpus" ] && [ -n "$spb" ] && [ -n "$cps" ] && [ -n "$tpc" ]; then
        nodehw="CPUs=$cpus Boards=${boards:-1} SocketsPerBoard=$spb CoresPerSocket=$cps ThreadsPerCore=$tpc"
    else
        nodehw="CPUs=$(nproc)"
    fi

    # ---- ports -----------------------------------------------------------------
    local ctld_port slurmd_port
    ctld_port=$(pick_port)
    slurmd_port=$(pick_port "$ctld_port")

    # ---- slurm.conf --------------------------------------------------------------
    : >"$DIR/etc/plugstack.conf"      # isolate from /etc/slurm/plugstack.conf
    cat >"$CONF" <<CONF
# generated by slurm_local.sh $(date -u +%FT%TZ)
ClusterName=local
# Must be \`hostname -s\` or slurmctld refuses to start ("not a valid controller").
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=$user
SlurmdUser=$user
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$MUNGE_SOCK
StateSaveLocation=$DIR/state
SlurmdSpoolDir=$DIR/spool
SlurmctldPidFile=$DIR/pid/slurmctld.pid
SlurmdPidFile=$DIR/pid/slurmd.pid
SlurmctldLogFile=$DIR/log/slurmctld.log
SlurmdLogFile=$DIR/log/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
PlugStackConfig=$DIR/etc/plugstack.conf
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/backfill
# default batch_sched_delay=3 adds ~3 s latency per scheduling round
SchedulerParameters=batch_sched_delay=0
MpiDefault=none
ReturnToService=2
PropagateResourceLimits=NONE
SwitchType=switch/none
MailProg=/bin/true
LaunchType=launch/slurm
KillWait=5
MinJobAge=300
SlurmdTimeout=60
InactiveLimit=0
MaxArraySize=10001
# reject impossible requests (e.g. --cpus-per-task > CPUs) at submit instead of pending forever
EnforcePartLimits=ALL
NodeName=$host NodeAddr=127.0.0.1 NodeHostname=$host $nodehw RealMemory=$mem State=UNKNOWN
PartitionName=debug Nodes=$host Default=YES MaxTime=INFINITE State=UP OverSubscribe=NO
CONF
    # No cgroup.conf: with proctrack/linuxproc + task/none + jobacct_gather/none
    # no cgroup plugin is loaded (Slurm would look for it next to slurm.conf).

    # ---- daemons (daemon mode, pid files) ----------------------------------------
    export SLURM_CONF=$CONF
    "$SLURMCTLD" -f "$CONF" -i </dev/null >>"$DIR/log/slurmctld.out" 2>&1 \
        || { dump_logs; do_stop; die "slurmctld failed to start"; }
    "$SLURMD" -f "$CONF" -N "$host" </dev/null >>"$DIR/log/slurmd.out" 2>&1 \
        || { dump_logs; do_stop; die "slurmd failed to start"; }

    # ---- wait for the node to be idle --------------------------------------------
    local state="" deadline=$(( SECONDS + SLURM_LOCAL_TIMEOUT ))
    while [ $SECONDS -lt $deadline ]; do
        state=$(timeout 10 "$SINFO" -h -N -n "$host" -o %T 2>/dev/null | head -n1 || true)
        case "$state" in idle|idle~|mixed|allocated) break ;; esac
        for f in slurmctld slurmd; do
            pid_alive "$(read_pid "$DIR/pid/$f.pid")" || { sleep 0.5; pid_alive "$(read_pid "$DIR/pid/$f.pid")" \
                || { dump_logs; do_stop; die "$f died during startup"; }; }
        done
        sleep 0.5
    done
    case "$state" in
        idle|idle~|mixed|allocated) ;;
        *) dump_logs; do_stop; die "node $host not idle after ${SLURM_LOCAL_TIMEOUT}s (state='$state')" ;;
    esac
    log "cluster up in $(( SECONDS - t0 ))s: node=$host state=$state ctld_port=$ctld_port slurmd_port=$slurmd_port"
    echo "export SLURM_CONF=$CONF"
}

case "$CMD" in
    start) do_start ;;
    stop)  do_stop ;;
    *) usage ;;
esac
