#!/usr/bin/env bash
# The grow stage on a real Slurm: brings up a single-node cluster (munged, slurmctld, slurmd on
# localhost, all as root, from Debian's slurm-wlm and munge) in a temporary folder, runs the
# shipped job array scripts/slurm/g2s-grow-array.sbatch over a tile store of several tiles and the
# stitch job as a dependent job (afterok), and checks that the mesh has the same bytes as
# `g2s mesh` with the same tile plan. Before that, one array task is cancelled (scancel) while it
# grows its block, and re-run with the whole array: the tiles it had grown are kept as they were.
# The cluster is torn down however the script ends.
#
#   scripts/slurm/test-slurm.sh [G2S-BINARY]     (default build/g2s; ctest runs it, label slurm)
#
# Where Slurm cannot run here (not root, the packages cannot be installed, the daemons do not
# start), it prints "SKIP: <reason>" and exits 0; with G2S_REQUIRE_SLURM=1 that is a failure.
set -euo pipefail
repo="$(cd "$(dirname "$0")/../.." && pwd)"
g2s="$(realpath "${1:-$repo/build/g2s}")"
sbatch_script="$repo/scripts/slurm/g2s-grow-array.sbatch"

skip() {
  echo "SKIP: $*"
  if [[ "${G2S_REQUIRE_SLURM:-0}" == 1 ]]; then exit 1; fi
  exit 0
}
fail() {
  echo "FAIL: $*" >&2
  exit 1
}

[[ -x "$g2s" ]] || fail "no g2s binary at $g2s (build first)"
[[ "$(id -u)" == 0 ]] || skip "the single-node Slurm needs root (to run slurmd and munged)"
if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null ||
  ! command -v sbatch >/dev/null || ! command -v munged >/dev/null; then
  echo "installing slurm-wlm and munge with apt-get"
  if ! { DEBIAN_FRONTEND=noninteractive apt-get install -y -q -o DPkg::Lock::Timeout=300 \
    --no-install-recommends slurm-wlm munge >/dev/null ||
    { apt-get update -q >/dev/null &&
      DEBIAN_FRONTEND=noninteractive apt-get install -y -q -o DPkg::Lock::Timeout=300 \
        --no-install-recommends slurm-wlm munge >/dev/null; }; }; then
    skip "slurm-wlm and munge could not be installed with apt-get"
  fi
fi

work="$(mktemp -d /tmp/g2s-slurm.XXXXXX)"
chmod 0700 "$work"
pids=()
teardown() {
  local status=$?
  # Cancel what is left and let the jobs' step daemons (slurmstepd) end with them, then stop the
  # daemons we started (their own pids, nothing else).
  if [[ -f "$work/slurm.conf" ]] && ((${#pids[@]})); then
    export SLURM_CONF="$work/slurm.conf"
    timeout 10 scancel --quiet --user=root 2>/dev/null || true
    for _ in $(seq 100); do
      [[ -z "$(timeout 5 squeue -h 2>/dev/null)" ]] && break
      sleep 0.1
    done
  fi
  for ((i = ${#pids[@]} - 1; i >= 0; i--)); do kill "${pids[i]}" 2>/dev/null || true; done
  for pid in "${pids[@]}"; do
    for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -9 "$pid" 2>/dev/null || true
  done
  if ((status != 0)) && [[ -d "$work/log" ]]; then
    for log in "$work"/log/*; do echo "--- $log" >&2; tail -n 20 "$log" >&2; done
  fi
  rm -rf "$work"
  exit "$status"
}
trap teardown EXIT
trap 'exit 130' INT TERM

# --- munge: a fresh key, its own socket and files in the temporary folder ---------------------
mkdir -p "$work/munge" "$work/log" "$work/state" "$work/spool" "$work/out"
chmod 0700 "$work/munge"
dd if=/dev/urandom of="$work/munge/munge.key" bs=1024 count=1 status=none
chmod 0400 "$work/munge/munge.key"
socket="$work/munge/munge.socket"
munged --foreground --force --key-file="$work/munge/munge.key" --socket="$socket" \
  --pid-file="$work/munge/munged.pid" --log-file="$work/log/munged.log" \
  --seed-file="$work/munge/munge.seed" >>"$work/log/munged.log" 2>&1 &
pids+=($!)
for _ in $(seq 50); do [[ -S "$socket" ]] && break; sleep 0.1; done
[[ -S "$socket" ]] || skip "munged did not start ($(tail -n 1 "$work/log/munged.log" 2>/dev/null))"

# --- slurm.conf for one node, this host, as root; no cgroup plugins (they need systemd) ------
host="$(hostname -s)"
cpus="$(nproc)"
memory_mb=$(($(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 / 2))
port=$((20000 + RANDOM % 20000))
cat >"$work/slurm.conf" <<EOF
ClusterName=g2stest
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$socket
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool/%n
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/log/slurmctld.log
SlurmdLogFile=$work/log/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
SwitchType=switch/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
SlurmctldTimeout=30
SlurmdTimeout=30
KillWait=2
MinJobAge=600
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$memory_mb State=UNKNOWN
PartitionName=test Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF="$work/slurm.conf"
slurmctld -D -i -f "$SLURM_CONF" >>"$work/log/slurmctld.out" 2>&1 &
pids+=($!)
slurmd -D -f "$SLURM_CONF" -N "$host" >>"$work/log/slurmd.out" 2>&1 &
pids+=($!)
state=""
for _ in $(seq 150); do
  state="$(sinfo -h -N -o '%T' 2>/dev/null | head -n 1 || true)"
  [[ "$state" == idle ]] && break
  sleep 0.2
done
if [[ "$state" != idle ]]; then
  skip "the Slurm daemons did not bring the node up (state '${state:-none}'; " \
    "$(tail -n 1 "$work/log/slurmctld.log" 2>/dev/null)" \
    "$(tail -n 1 "$work/log/slurmd.log" 2>/dev/null))"
fi
echo "slurm: node $host up ($cpus CPUs), $(sinfo -V)"

# Waits until none of the given jobs (array jobs with all their tasks) is pending or running,
# then checks that every one ended in the state wanted.
wait_jobs() {
  local want="$1"
  shift
  local ids
  ids="$(IFS=,; echo "$*")"
  for _ in $(seq 1200); do
    [[ -z "$(squeue -h -j "$ids" 2>/dev/null)" ]] && break
    sleep 0.1
  done
  local id states
  for id in "$@"; do
    states="$(scontrol -o show job "$id" | grep -o 'JobState=[A-Z_]*' | sort | uniq -c)"
    [[ -n "$states" ]] || fail "job $id: scontrol knows nothing of it"
    if grep -qv "JobState=$want\$" <<<"$states"; then
      fail "job $id ended with $(tr '\n' ' ' <<<"$states")(wanted $want)"
    fi
  done
}

# --- the tile store: a noisy open terrain, cut into tiles of a few hundred thousand points ---
# Tiles big enough that a task still grows its block when it is cancelled.
tile_points=150000
"$g2s" synth terrain --points 1500000 --noise 0.1 --seed 7 -o "$work/cloud.ply" >/dev/null
"$g2s" tile "$work/cloud.ply" "$work/cloud.store" --tile-points "$tile_points" --quiet
tiles="$("$g2s" tile-info "$work/cloud.store" | awk '/^tiles:/ {print $2}')"
block=4
tasks=$(((tiles + block - 1) / block))
((tasks >= 3)) || fail "the store has only $tiles tiles"
echo "store: $tiles tiles, $tasks array tasks of $block tiles"
PATH="$(dirname "$g2s"):$PATH"
export PATH
submit=(sbatch --parsable --cpus-per-task=1 --mem=512M --time=10:00
  --output="$work/out/%x-%A_%a.out" --chdir="$work"
  --export="ALL,STORE=$work/cloud.store,TILES=$tiles,BLOCK=$block")

# --- one task cancelled while it grows its block ----------------------------------------------
victim=1
grown="$work/cloud.store.grown"
first_tile=$((victim * block))
job="$(
  "${submit[@]}" --array="$victim" "$sbatch_script"
)"
first_file="$grown/$(printf 'tile-%06d.g2sgrow' "$first_tile")"
for _ in $(seq 3000); do
  [[ -f "$first_file" ]] && break
  [[ -n "$(squeue -h -j "$job" 2>/dev/null)" ]] || break
  sleep 0.02
done
scancel "${job}_${victim}"
wait_jobs CANCELLED "$job"
kept=()
for ((t = first_tile; t < first_tile + block; t++)); do
  file="$grown/$(printf 'tile-%06d.g2sgrow' "$t")"
  [[ -f "$file" ]] && kept+=("$file")
done
if ((${#kept[@]} == 0 || ${#kept[@]} == block)); then
  fail "task $victim was cancelled with ${#kept[@]} of its $block tiles grown (wanted some, not all)"
fi
before="$(stat -c '%n %i %y %s' "${kept[@]}")"
echo "cancelled task ${job}_$victim with ${#kept[@]} of its $block tiles grown"

# --- the whole array (re-running the cancelled task), then stitch after it ------------------
array="$("${submit[@]}" --array="0-$((tasks - 1))" "$sbatch_script")"
stitch="$(sbatch --parsable --dependency="afterok:$array" --cpus-per-task=1 --mem=512M \
  --time=10:00 --output="$work/out/stitch-%j.out" --chdir="$work" --export=ALL \
  --wrap "g2s stitch '$work/cloud.store' -o '$work/slurm.stl' --quiet")"
wait_jobs COMPLETED "$array" "$stitch"
after="$(stat -c '%n %i %y %s' "${kept[@]}")"
[[ "$before" == "$after" ]] || fail "the re-run grew again tiles the cancelled task had grown"

# --- the same tile plan in one process ------------------------------------------------------
"$g2s" mesh "$work/cloud.ply" -o "$work/mesh.stl" --tile-points "$tile_points" --quiet --no-stats
cmp "$work/slurm.stl" "$work/mesh.stl" || fail "Slurm's mesh differs from g2s mesh"
echo "PASS: $tiles tiles over $tasks array tasks + afterok stitch = g2s mesh," \
  "$(stat -c %s "$work/mesh.stl") bytes; the cancelled task's ${#kept[@]} grown tiles were kept"
