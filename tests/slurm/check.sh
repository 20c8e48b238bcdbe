#!/usr/bin/env bash
# The SLURM backend of `monolayer sweep` against a real SLURM: installs Debian's slurm-wlm and
# munge if missing, starts munged, slurmctld and slurmd as a one-node cluster on this machine
# (every file in a scratch directory, SLURM_CONF pointing there), submits a tiny sweep with
# `--backend slurm --submit`, waits for it, collects summary.csv, runs the same sweep with the
# local backend, and checks that the two summaries are identical; then stops a running task with
# SIGTERM (the warning signal the script asks for) and checks that it is requeued, resumes from
# its checkpoint and ends byte-identical to a local run. Stops the daemons at the end.
#
#   bash tests/slurm/check.sh
#
# Needs root (it is, on these machines).
set -euo pipefail
cd "$(dirname "$0")/../.."

if ! command -v sbatch >/dev/null || ! command -v munged >/dev/null; then
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq slurm-wlm munge >/dev/null
fi
# MONOLAYER_BIN: a binary built already (.ci/run passes the test build's, so that CI does not
# build the workspace's dependencies a second time with another feature set).
if [ -n "${MONOLAYER_BIN:-}" ]; then
    bin="$MONOLAYER_BIN"
else
    cargo build --release --locked -p monolayer-cli
    bin="$PWD/target/release/monolayer"
fi

work=$(mktemp -d /tmp/monolayer-slurm.XXXXXX)
export SLURM_CONF="$work/slurm.conf"
host=$(hostname)
cleanup() {
    for f in "$work/slurmd.pid" "$work/slurmctld.pid" "$work/munged.pid"; do
        [ -f "$f" ] || continue
        pid=$(cat "$f")
        kill "$pid" 2>/dev/null || continue
        for _ in $(seq 1 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.2; done
        kill -9 "$pid" 2>/dev/null || true
    done
}
trap cleanup EXIT

# munge: a key, its directories, the daemon as user munge.
mkdir -p /etc/munge /run/munge /var/log/munge /var/lib/munge
if [ ! -s /etc/munge/munge.key ]; then
    dd if=/dev/urandom of=/etc/munge/munge.key bs=1024 count=1 status=none
fi
chown -R munge:munge /etc/munge /run/munge /var/log/munge /var/lib/munge
chmod 400 /etc/munge/munge.key
runuser -u munge -- /usr/sbin/munged --pid-file="$work/munged.pid.tmp" \
    || { echo "munged did not start"; exit 1; }
sleep 1
cp "$work/munged.pid.tmp" "$work/munged.pid" 2>/dev/null || pgrep -n munged > "$work/munged.pid"

# slurm: one node with this machine's cores, everything under $work.
mem_mib=$(( $(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 - 1024 ))
mkdir -p "$work/state" "$work/spool"
cat > "$SLURM_CONF" <<CONF
ClusterName=monolayer-check
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
NodeName=$host CPUs=$(nproc) RealMemory=$mem_mib State=UNKNOWN
PartitionName=check Nodes=$host Default=YES MaxTime=INFINITE State=UP
# A requeued job waits CredExpire + 1 s before it may start again (default 120 s).
AuthInfo=cred_expire=5
CONF
/usr/sbin/slurmctld
/usr/sbin/slurmd
for _ in $(seq 1 60); do
    sinfo -h -o %t 2>/dev/null | grep -q idle && break
    sleep 1
done
sinfo -h -o %t | grep -q idle || { echo "the node never became idle"; cat "$work"/slurm*.log; exit 1; }
echo "SLURM up: $(sinfo -h -o '%P %D %t %c')"

# The same tiny sweep (2 activities × 2 seeds of the paper scene, 10 + 10 TU) both ways.
args=(scenes/paper.toml --vary model.zeta=0,0.005 --seeds 1-2 --set run.relax_time=10 --set run.time=10)
"$bin" sweep "${args[@]}" --out "$work/slurm" --backend slurm --submit
for _ in $(seq 1 300); do
    [ -z "$(squeue -h 2>/dev/null)" ] && break
    sleep 1
done
[ -z "$(squeue -h)" ] || { echo "the job array did not finish in 300 s"; squeue; exit 1; }
"$bin" sweep --collect --out "$work/slurm"
"$bin" sweep "${args[@]}" --out "$work/local" --jobs 2 --quiet
if cmp "$work/slurm/summary.csv" "$work/local/summary.csv"; then
    echo "summary.csv of the SLURM backend is identical to the local backend's ($(($(wc -l < "$work/local/summary.csv") - 1)) runs):"
    cat "$work/slurm/summary.csv"
else
    echo "summary.csv differs between the backends:"
    diff "$work/slurm/summary.csv" "$work/local/summary.csv" || true
    exit 1
fi

# A task stopped by SLURM's warning signal (the script asks for SIGTERM before the time limit;
# here it is sent by hand, as slurmctld would) writes a checkpoint, is requeued, resumes from
# it, and ends with the same files as the same run done locally in one go.
args=(scenes/paper.toml --vary model.zeta=0.005 --set run.relax_time=10 --set run.time=1500
      --set run.output_every=100)
"$bin" sweep "${args[@]}" --out "$work/requeue" --backend slurm --submit --threads 1
run="$work/requeue/runs/model.zeta=0.005_seed=1"
for _ in $(seq 1 300); do
    [ -s "$run/.lock" ] && break
    sleep 0.2
done
sleep 1
job=$(squeue -h -o %A | head -n 1)
scancel --batch --signal=TERM "$job"
for _ in $(seq 1 120); do
    grep -q "stopped at step" "$work/requeue/slurm/0.out" 2>/dev/null && break
    sleep 0.5
done
grep -q "stopped at step" "$work/requeue/slurm/0.out" \
    || { echo "the task did not stop on SIGTERM"; cat "$work/requeue/slurm/0.out"; squeue; exit 1; }
for _ in $(seq 1 300); do
    [ -z "$(squeue -h 2>/dev/null)" ] && break
    sleep 1
done
[ -z "$(squeue -h)" ] || { echo "the requeued task did not finish in 300 s"; squeue; exit 1; }
cmp -s "$run/scene.toml" "$run/complete" || { echo "the requeued run is not complete"; cat "$work/requeue/slurm/0.out"; exit 1; }
"$bin" sweep "${args[@]}" --out "$work/requeue-local" --quiet
local_run="$work/requeue-local/runs/model.zeta=0.005_seed=1"
if diff -r "$run/frames" "$local_run/frames" && cmp "$run/series.csv" "$local_run/series.csv"; then
    echo "a task $(grep -o 'stopped at step [0-9]*' "$work/requeue/slurm/0.out") by SIGTERM, was requeued, resumed from its checkpoint and ended byte-identical to a local run"
else
    echo "the requeued run differs from the local one"; exit 1
fi
