#!/usr/bin/env bash
# Runs a sweep on a real SLURM scheduler and checks the merged table is byte-identical to a
# local run: installs Debian's slurm-wlm and munge if missing, starts a single-node cluster
# (this machine; munged, slurmctld, slurmd), submits the sweep as a job array (one shard per
# task, the recipe of examples/sweeps/slurm-array.sh) plus a merge job that depends on it, waits,
# compares, and stops the daemons. Root only (the daemons and apt-get need it).
#
#   bash scripts/slurm-check.sh [SPEC] [TASKS]     (default examples/sweeps/amplitude.toml, 4)
#
# Opt-in test: `cargo test --release -p moreau --test slurm -- --ignored`.
set -euo pipefail
cd "$(dirname "$0")/.."
SPEC=${1:-examples/sweeps/amplitude.toml}
TASKS=${2:-4}
[ "$(id -u)" = 0 ] || { echo "slurm-check: run as root (starts slurmctld, slurmd, munged)" >&2; exit 2; }

if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
    echo "slurm-check: installing slurm-wlm and munge" >&2
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends slurm-wlm munge >/dev/null
fi
MOREAU=${MOREAU:-$PWD/target/release/moreau}
[ -x "$MOREAU" ] || cargo build --release -q -p moreau
WORK=$(mktemp -d /tmp/moreau-slurm.XXXXXX)
HOST=$(hostname -s)
CPUS=$(nproc)

cleanup() {
    scancel --user=root >/dev/null 2>&1 || true
    [ -f "$WORK/slurmd.pid" ] && kill "$(cat "$WORK/slurmd.pid")" 2>/dev/null || true
    [ -f "$WORK/slurmctld.pid" ] && kill "$(cat "$WORK/slurmctld.pid")" 2>/dev/null || true
    [ -f "$WORK/munged.pid" ] && kill "$(cat "$WORK/munged.pid")" 2>/dev/null || true
}
trap cleanup EXIT

# munge: a key and the daemon
mkdir -p /etc/munge /var/lib/munge /var/log/munge /run/munge "$WORK/spool/d" "$WORK/spool/ctld"
[ -s /etc/munge/munge.key ] || mungekey --create --keyfile=/etc/munge/munge.key >/dev/null 2>&1 \
    || dd if=/dev/urandom of=/etc/munge/munge.key bs=1024 count=1 2>/dev/null
chown -R munge:munge /etc/munge /var/lib/munge /var/log/munge /run/munge 2>/dev/null || true
chmod 0700 /etc/munge
chmod 0400 /etc/munge/munge.key
munged --force --pid-file="$WORK/munged.pid" 2>/dev/null || munged --force
sleep 1

# a single-node cluster: this machine, all its cores, no cgroups, no accounting
mkdir -p /etc/slurm
cat > /etc/slurm/slurm.conf <<EOF
ClusterName=moreau-check
SlurmctldHost=$HOST
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
StateSaveLocation=$WORK/spool/ctld
SlurmdSpoolDir=$WORK/spool/d
SlurmctldPidFile=$WORK/slurmctld.pid
SlurmdPidFile=$WORK/slurmd.pid
SlurmctldLogFile=$WORK/slurmctld.log
SlurmdLogFile=$WORK/slurmd.log
NodeName=$HOST NodeAddr=127.0.0.1 CPUs=$CPUS State=UNKNOWN
PartitionName=check Nodes=$HOST Default=YES MaxTime=INFINITE State=UP
EOF
slurmctld -c -i
slurmd -c
for _ in $(seq 60); do
    sinfo -h -o %T 2>/dev/null | grep -qE "idle|mix|alloc" && break
    sleep 1
done
sinfo -h -o "%P %T %D %C" || { echo "slurm-check: the cluster did not come up" >&2; tail -5 "$WORK"/slurm*.log >&2; exit 1; }

# the sweep as a job array (one shard per task) and a dependent merge job
SHARDS="$WORK/shards"
ARRAY=$(sbatch --parsable --array=0-$((TASKS - 1)) --cpus-per-task=1 --chdir="$PWD" \
    --output="$WORK/task-%a.out" --job-name=moreau-sweep \
    --wrap "$MOREAU sweep $SPEC --out $SHARDS --shard \${SLURM_ARRAY_TASK_ID}/$TASKS --threads 1 --quiet")
MERGE=$(sbatch --parsable --dependency=afterok:"$ARRAY" --chdir="$PWD" --output="$WORK/merge.out" \
    --job-name=moreau-merge --wrap "$MOREAU merge $SHARDS --out $WORK/merged")
echo "slurm-check: array job $ARRAY ($TASKS tasks), merge job $MERGE"
for _ in $(seq 900); do
    [ -z "$(squeue -h -j "$ARRAY,$MERGE" 2>/dev/null)" ] && break
    sleep 1
done
[ -f "$WORK/merged/sweep.tex" ] || { echo "slurm-check: no merged table" >&2; cat "$WORK"/*.out >&2 || true; exit 1; }

# the same sweep locally, then byte-for-byte comparison of every table
"$MOREAU" sweep "$SPEC" --out "$WORK/local" --quiet
for f in sweep.csv sweep.md sweep.tex; do
    cmp "$WORK/merged/$f" "$WORK/local/$f" || { echo "slurm-check: $f differs" >&2; exit 1; }
done
echo "slurm-check: OK - $TASKS-task job array + dependent merge on SLURM $(sinfo -V | cut -d' ' -f2) give tables byte-identical to a local run ($WORK)"
