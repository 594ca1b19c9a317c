#!/usr/bin/env bash
# A real single-node Slurm (docs/cluster.md): installs slurm-wlm and munge from Debian's
# packages, starts munged, slurmctld and slurmd on localhost (no systemd, no cgroups), and runs
# the sbatch script and the submit lines of docs/cluster.md taken from the page itself (the
# blocks between `<!-- slurm-test: NAME -->` and `<!-- /slurm-test -->`), on a small study in 4
# shards:
#   1. the array and the merge job (--dependency=afterany): merged table == unsharded run in
#      every column but wall_s;
#   2. again with one task cancelled (scancel): the merge job exits 1 naming its shard; the page's
#      rerun command runs that shard; a merge is then complete and equal to the unsharded run.
# Needs root on Debian (as CI is) and target/release/flexstar (built by `cargo test --release`);
# elsewhere it says why it skips and exits 0. Every daemon it starts is stopped by its pid.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
BIN=$ROOT/target/release/flexstar
PAGE=$ROOT/docs/cluster.md
started=$(date +%s)

skip() { echo "slurm test: skipped: $*"; exit 0; }
[ "$(id -u)" = 0 ] || skip "not root (it installs packages and starts daemons)"
grep -qi '^ID=debian' /etc/os-release 2>/dev/null || skip "not Debian (it installs Debian's slurm-wlm)"
[ -x "$BIN" ] || { echo "slurm test: $BIN missing: run cargo test --workspace --release first" >&2; exit 1; }

if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends slurm-wlm munge >/dev/null
fi
echo "slurm test: packages ready after $(( $(date +%s) - started )) s"

T=$(mktemp -d /tmp/flexstar-slurm.XXXXXX)
chmod 755 "$T" # the munge user reaches its folder inside
PIDS=()
cleanup() {
    for p in "${PIDS[@]}"; do kill "$p" 2>/dev/null || true; done
    for p in "${PIDS[@]}"; do wait "$p" 2>/dev/null || true; done
    rm -rf "$T"
}
trap cleanup EXIT

# --- munge: its own socket and files in $T (owned by the munge user, as munged demands)
install -d -o munge -g munge -m 0711 "$T/munge"
runuser -u munge -- /usr/sbin/munged --foreground --socket="$T/munge/sock" \
    --pid-file="$T/munge/pid" --log-file="$T/munge/log" --seed-file="$T/munge/seed" \
    --key-file=/etc/munge/munge.key >"$T/munged.out" 2>&1 &
PIDS+=($!)
for _ in $(seq 50); do [ -S "$T/munge/sock" ] && break; sleep 0.1; done
[ -S "$T/munge/sock" ] || { echo "munged did not start:"; cat "$T/munged.out" "$T/munge/log"; exit 1; }

# --- slurm: one node, this machine, as slurmd -C describes it
mkdir -p "$T/state" "$T/spool"
NODE=$(slurmd -C | head -1)
NODENAME=$(sed 's/^NodeName=\([^ ]*\).*/\1/' <<<"$NODE")
export SLURM_CONF=$T/slurm.conf
cat >"$SLURM_CONF" <<EOF
ClusterName=flexstar-ci
SlurmctldHost=localhost(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$T/munge/sock
CredType=cred/munge
StateSaveLocation=$T/state
SlurmdSpoolDir=$T/spool
SlurmctldPidFile=$T/slurmctld.pid
SlurmdPidFile=$T/slurmd.pid
SlurmctldLogFile=$T/slurmctld.log
SlurmdLogFile=$T/slurmd.log
SlurmctldPort=16817
SlurmdPort=16818
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
ReturnToService=2
MinJobAge=600
SchedulerParameters=sched_interval=2
$NODE NodeAddr=127.0.0.1 State=UNKNOWN
PartitionName=ci Nodes=$NODENAME Default=YES MaxTime=INFINITE State=UP OverSubscribe=NO
EOF
/usr/sbin/slurmctld -D -i >"$T/slurmctld.out" 2>&1 &
PIDS+=($!)
/usr/sbin/slurmd -D >"$T/slurmd.out" 2>&1 &
PIDS+=($!)
for _ in $(seq 100); do
    sinfo -h -o %T 2>/dev/null | grep -qE '^(idle|mixed|allocated)' && break
    sleep 0.2
done
sinfo -h -o %T | grep -qE '^(idle|mixed|allocated)' || { echo "slurm did not come up:"; tail -n 20 "$T"/slurm*.log; exit 1; }
echo "slurm test: slurm up after $(( $(date +%s) - started )) s ($(sinfo -h -o '%n %c CPUs'))"

# --- the page's blocks
block() { # the text between <!-- slurm-test: $1 --> and <!-- /slurm-test --> without the fences
    awk -v name="$1" '$0 == "<!-- slurm-test: " name " -->" {on=1; next}
        on && $0 == "<!-- /slurm-test -->" {exit} on && !/^```/ {print}' "$PAGE"
}
replace() { # replace() FROM TO FILE: fail when FROM is not in FILE (the page changed)
    grep -qF -- "$1" "$3" || { echo "slurm test: '$1' not in the page's block $3" >&2; exit 1; }
    sed -i "s|$1|$2|g" "$3"
}

# a work folder standing for the repository root: the binary, the study, its base
W=$T/work
mkdir -p "$W/target/release" "$W/configs/studies"
ln -s "$BIN" "$W/target/release/flexstar"
cp "$ROOT/tests/data/tiny.toml" "$W/configs/studies/base.toml"
cat >"$W/configs/studies/ci.toml" <<'EOF'
name = "ci"
base = "base.toml"
solvers = ["amm"]
[[vary]]
key = "robot.Lp"
values = [0.02, 0.03, 0.04]
[[vary]]
key = "robot.Jp"
linspace = [1e-4, 4e-4, 4]
EOF
block sbatch >"$W/sweep.sbatch"
block submit >"$W/submit.sh"
block rerun >"$W/rerun.sh"
for f in sweep.sbatch submit.sh rerun.sh; do [ -s "$W/$f" ] || { echo "slurm test: no block for $f in $PAGE" >&2; exit 1; }; done
replace "--cpus-per-task=8" "--cpus-per-task=1" "$W/sweep.sbatch"
replace "--time=02:00:00" "--time=00:05:00" "$W/sweep.sbatch"
for f in submit.sh rerun.sh; do replace "configs/studies/sleeve.toml" "configs/studies/ci.toml" "$W/$f"; done
replace "out/studies/sleeve" "out/studies/ci" "$W/submit.sh"
replace "N=64" "N=4" "$W/submit.sh"
replace "N=64" "N=4" "$W/rerun.sh"
replace "--array=3,17" "--array=2" "$W/rerun.sh"

# the reference: the unsharded study, run directly
cd "$W"
"$BIN" sweep configs/studies/ci.toml --out ref --no-plots --jobs 2 2>/dev/null
without_wall() { # a results table without its wall_s column
    local col
    col=$(head -1 "$1" | tr ',' '\n' | grep -nx wall_s | cut -d: -f1)
    cut -d, --complement -f"$col" "$1"
}
wait_idle() { # until no job of ours is pending or running
    for _ in $(seq 300); do [ -z "$(squeue -h -o %i)" ] && return 0; sleep 0.2; done
    echo "slurm test: jobs still queued:"; squeue; exit 1
}
merge_job() { # the id of the latest merge job (the --wrap one)
    scontrol show job -o | grep -F 'JobName=wrap' | sed 's/^JobId=\([0-9]*\).*/\1/' | sort -n | tail -1
}
exit_of() { scontrol show job -o "$1" | sed 's/.*ExitCode=\([0-9]*\):.*/\1/'; }

# 1. the whole array and the merge job, as the page says
bash -euo pipefail submit.sh
wait_idle
mj=$(merge_job)
[ "$(exit_of "$mj")" = 0 ] || { echo "slurm test: merge job $mj failed:"; cat logs/merge-"$mj".out; exit 1; }
diff <(without_wall ref/ci/results.csv) <(without_wall out/studies/ci/results.csv) >/dev/null \
    || { echo "slurm test: merged table differs from the unsharded run"; exit 1; }
[ "$(wc -l <out/studies/ci/results.csv)" = 13 ] || { echo "slurm test: expected 12 rows"; exit 1; }
echo "slurm test: 4 shards + merge equal the unsharded study ($(( $(date +%s) - started )) s)"

# 2. the same with task 2 cancelled before it runs (the array is submitted held, then released)
rm -rf out logs/*
export SBATCH_HOLD=1
bash -euo pipefail submit.sh
unset SBATCH_HOLD
array=$(squeue -h -o '%F %j' | awk '$2 == "flexstar-sweep" {print $1; exit}')
scancel "${array}_2"
for id in $(squeue -h -t PD -o %i); do scontrol release "$id" 2>/dev/null || true; done
wait_idle
mj=$(merge_job)
[ "$(exit_of "$mj")" = 1 ] || { echo "slurm test: merge job $mj should exit 1:"; cat logs/merge-"$mj".out; exit 1; }
grep -q 'shard(s) \[2\] missing' logs/merge-"$mj".out \
    || { echo "slurm test: the merge does not name shard 2:"; cat logs/merge-"$mj".out; exit 1; }
bash -euo pipefail rerun.sh
wait_idle
"$BIN" sweep merge out/studies/ci --no-plots 2>merge.log || { cat merge.log; exit 1; }
diff <(without_wall ref/ci/results.csv) <(without_wall out/studies/ci/results.csv) >/dev/null \
    || { echo "slurm test: merged table after the rerun differs from the unsharded run"; exit 1; }
echo "slurm test: task 2 cancelled, merge exit 1 naming shard 2, rerun, merge complete"
echo "slurm test: passed in $(( $(date +%s) - started )) s"
