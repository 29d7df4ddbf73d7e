#!/usr/bin/env bash
# Starts a real single-node Slurm cluster (munged, slurmctld, slurmd with a
# generated slurm.conf in a temporary directory) inside private network and
# PID namespaces, so that it listens on that namespace's loopback only and
# every daemon dies with the test whatever happens; then, through
# scripts/slurm/sweep.sh:
#   1. a 4-shard sweep of SCENE, whose merge must equal a single-process run's
#      aggregates exactly, with sbatch arguments after -- that both the array
#      and the merge job must carry (--time);
#   2. a 4-shard sweep with task 2 cancelled (scancel): the merge job must fail
#      naming shard 2/4, the harness's rerun command (with its -o) and the
#      sweep.sh command that resubmits it with the same sbatch arguments;
#      resubmitting only task 2 and the merge completes the run, equal again
#      to the single-process run.
# Exit 77 (ctest SKIP), with the reason, when Slurm or munge is not installed
# or the daemons cannot run on this machine.
#   slurm_sweep.sh HARNESS_EXE SOURCE_DIR SCENE
set -euo pipefail
harness=$(readlink -f "$1") src=$(readlink -f "$2") scene=$(readlink -f "$3")
here=$(cd "$(dirname "$0")" && pwd)
skip() {
  echo "SKIP: $*"
  exit 77
}
fail() {
  echo "FAIL: $*"
  exit 1
}

if [[ -z ${IDCOL_SLURM_TEST_NS:-} ]]; then
  for b in munged slurmctld slurmd sbatch scontrol scancel sinfo unshare ip python3; do
    command -v "$b" > /dev/null ||
      skip "$b is not installed (scripts/setup.sh installs slurmctld, slurmd, slurm-client and munge)"
  done
  [[ $(id -u) -eq 0 ]] || skip "needs root to create network and PID namespaces and run slurmd (running as $(id -un))"
  if ! err=$(unshare --net --pid --mount --uts --fork --mount-proc true 2>&1); then
    skip "cannot create private network and PID namespaces (unshare: $err); the test runs Slurm only on a private loopback"
  fi
  # Everything below runs in the namespaces; when their first process ends
  # (or is killed by this bounded timeout), the kernel kills every daemon.
  IDCOL_SLURM_TEST_NS=1 exec timeout -s KILL 840 unshare --net --pid --mount --uts --fork --mount-proc --kill-child \
    bash "$0" "$@"
fi

ip link set lo up
# glibc's getaddrinfo(AI_ADDRCONFIG), which Slurm uses, finds no IPv4 address
# unless one other than 127.0.0.1 is configured: add a second loopback one.
ip addr add 127.0.0.2/8 dev lo
work=$(mktemp -d "${TMPDIR:-/tmp}/idcol-slurm.XXXXXX")
# munged wants its socket's directory searchable by all.
chmod 711 "$work"
# The cluster's host names, seen only inside this mount namespace.
printf '127.0.0.1 localhost idcol-node\n' > "$work/hosts"
mount --bind "$work/hosts" /etc/hosts
hostname idcol-node
pids=()
cleanup() {
  local rc=$?
  trap - EXIT INT TERM
  for p in "${pids[@]}"; do kill -TERM "$p" 2> /dev/null || true; done
  sleep 1
  for p in "${pids[@]}"; do kill -KILL "$p" 2> /dev/null || true; done
  if ((rc != 0 && rc != 77)); then
    for log in "$work"/*.log "$work"/out*/logs/*; do
      [[ -f $log ]] && { echo "---- $log (last 30 lines)"; tail -30 "$log"; }
    done
  fi
  if [[ -n ${IDCOL_SLURM_TEST_KEEP:-} ]]; then echo "kept $work"; else rm -rf "$work"; fi
  exit "$rc"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

# munge with its own key and socket, nothing shared with a system munged.
dd if=/dev/urandom of="$work/munge.key" bs=1024 count=1 status=none
chmod 400 "$work/munge.key"
munged --force --foreground --key-file="$work/munge.key" --socket="$work/munge.socket" \
  --pid-file="$work/munged.pid" --log-file="$work/munged.log" --seed-file="$work/munge.seed" > "$work/munged.stdout" 2>&1 &
pids+=($!)
for _ in $(seq 100); do [[ -S $work/munge.socket ]] && break; sleep 0.1; done
[[ -S $work/munge.socket ]] || skip "munged did not start: $(tail -5 "$work/munged.log" 2> /dev/null)"

cpus=$(nproc)
mkdir -p "$work/state" "$work/spool"
export SLURM_CONF=$work/slurm.conf
cat > "$SLURM_CONF" << CONF
ClusterName=idcoltest
SlurmctldHost=idcol-node(127.0.0.1)
MailProg=/bin/true
CommunicationParameters=NoCtldInAddrAny,NoInAddrAny
SlurmUser=root
SlurmdUser=root
SlurmctldPort=6817
SlurmdPort=6818
AuthType=auth/munge
AuthInfo=socket=$work/munge.socket
CredType=cred/munge
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
ProctrackType=proctrack/linuxproc
TaskPlugin=task/affinity
TaskPluginParam=Cores
MpiDefault=none
SwitchType=switch/none
ReturnToService=2
SchedulerType=sched/backfill
# Schedule (and evaluate the merge's dependency) every second, not every minute.
SchedulerParameters=sched_interval=1,bf_interval=1
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
JobCompType=jobcomp/none
MinJobAge=600
SlurmdTimeout=60
InactiveLimit=0
KillWait=5
NodeName=idcol-node NodeAddr=127.0.0.1 NodeHostname=idcol-node CPUs=$cpus State=UNKNOWN
PartitionName=idcol Nodes=idcol-node Default=YES MaxTime=30 State=UP
CONF
slurmctld -D -i > "$work/slurmctld.stdout" 2>&1 &
pids+=($!)
slurmd -D -N idcol-node > "$work/slurmd.stdout" 2>&1 &
pids+=($!)
deadline=$((SECONDS + 60))
until sinfo -h -n idcol-node -o %T 2> /dev/null | grep -qE '^(idle|mixed|allocated)'; do
  if ((SECONDS > deadline)); then
    skip "the single-node Slurm cluster did not come up within 60 s (node state '$(sinfo -h -o %T 2>&1)');" \
      "slurmctld: $(tail -3 "$work/slurmctld.log" 2> /dev/null | tr '\n' ' ') slurmd: $(tail -3 "$work/slurmd.log" 2> /dev/null | tr '\n' ' ')"
  fi
  for p in "${pids[@]}"; do
    kill -0 "$p" 2> /dev/null ||
      skip "a Slurm daemon exited at start: $(cat "$work"/slurm*.stdout | tail -5 | tr '\n' ' ') $(tail -3 "$work"/slurm*.log 2> /dev/null | tr '\n' ' ')"
  done
  sleep 0.5
done
echo "== [${SECONDS}s] single-node Slurm cluster up ($(sinfo -h -o '%P %D %c %T'), $(sinfo -V)), loopback of a private network namespace"

# Waits for a job to end (bounded) and prints its final state.
wait_job() {
  local id=$1 limit=$2 state
  local deadline=$((SECONDS + limit))
  while :; do
    state=$(scontrol show job "$id" 2> /dev/null | grep -o 'JobState=[A-Z_]*' | head -1 | cut -d= -f2)
    case $state in
      COMPLETED | FAILED | CANCELLED | TIMEOUT | NODE_FAIL | OUT_OF_MEMORY | PREEMPTED | BOOT_FAIL | DEADLINE)
        echo "$state"
        return
        ;;
    esac
    if ((SECONDS > deadline)); then
      echo "STILL_${state:-UNKNOWN}_AFTER_${limit}s"
      return
    fi
    sleep 1
  done
}
sweep() { "$src/scripts/slurm/sweep.sh" "$@" | tee /dev/stderr | awk '/^IDCOL_SWEEP_JOBS/ {print $2, $3}'; }
export IDCOL_HARNESS=$harness

echo "== [${SECONDS}s] single-process reference"
"$harness" run "$scene" -o "$work/whole.json" --failures "$work/whole.failures.json" --no-progress > /dev/null

echo "== [${SECONDS}s] 4-shard sweep through scripts/slurm/sweep.sh"
read -r array merge < <(sweep "$scene" "$work/out" --shards 4 -- --time=7)
[[ -n ${merge:-} ]] || fail "sweep.sh printed no job ids"
state=$(wait_job "$merge" 300)
[[ $state == COMPLETED ]] || fail "merge job $merge ended $state"
# The sbatch arguments reach both jobs (the merge once ran under the
# partition's default time limit, account and partition).
for job in "${array}_0" "$merge"; do
  scontrol show job "$job" | grep -q "TimeLimit=00:07:00" ||
    fail "job $job did not get --time=7: $(scontrol show job "$job" | grep -o 'TimeLimit=[^ ]*')"
done
python3 "$here/same_aggregates.py" "$work/out/merged.json" "$work/whole.json"
n=$(python3 -c 'import json,sys; print(len(json.load(open(sys.argv[1]))["shard"]["merged_from"]))' "$work/out/merged.json")
[[ $n == 4 ]] || fail "merged from $n shards, expected 4"
grep -h "^shard" "$work"/out/logs/shard-*.out

echo "== [${SECONDS}s] 4-shard sweep with task 2 cancelled"
read -r array merge < <(sweep "$scene" "$work/out2" --shards 4 -- --hold --time=7)
scancel "${array}_2"
scontrol release "$array"
scontrol release "$merge"
state=$(wait_job "$merge" 300)
[[ $state == FAILED ]] || fail "merge job $merge ended $state with task ${array}_2 cancelled, expected FAILED"
cat "$work"/out2/logs/merge-"$merge".out
grep -qF "shard 2/4 is missing" "$work/out2/logs/merge-$merge.out" ||
  fail "the merge job's message does not name shard 2/4"
grep -qF -- "-o $work/out2/shards/2.json --shard 2/4\`" "$work/out2/logs/merge-$merge.out" ||
  fail "the merge job's message does not give the rerun's -o"
grep -qF -- "scripts/slurm/sweep.sh $scene $work/out2 --shards 4 --only 2 -- --hold --time=7" "$work/out2/logs/merge-$merge.out" ||
  fail "the merge job's message does not give the resubmission with the sweep's sbatch arguments"
for i in 0 1 3; do [[ -f $work/out2/shards/$i.json ]] || fail "shard $i/4 did not complete"; done
[[ ! -e $work/out2/merged.json ]] || fail "a failed merge left merged.json"

echo "== [${SECONDS}s] resubmit only task 2, and the merge"
read -r array merge < <(sweep "$scene" "$work/out2" --shards 4 --only 2)
state=$(wait_job "$merge" 300)
[[ $state == COMPLETED ]] || fail "merge job $merge after the rerun ended $state"
python3 "$here/same_aggregates.py" "$work/out2/merged.json" "$work/whole.json"
echo "PASS"
