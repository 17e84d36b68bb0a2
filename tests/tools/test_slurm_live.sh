#!/usr/bin/env bash
# A study through a live Slurm. Starts a single-node cluster on this machine (munged, slurmctld
# and slurmd from a generated slurm.conf, with their key, socket, state, spool, logs and pid files
# in a temporary folder and on free ports of their own), submits the quick variant of model_error
# with `mcfbench submit --tasks 3`, cancels one array task while it runs, waits for the jobs to
# end, submits again, and checks that
#   - a second submission while the first one's jobs are queued is refused;
#   - the first collect-and-report job failed naming the cells the cancelled task lost;
#   - the second submission ran only that task's shard, leaving the finished cells' files as they
#     were;
#   - `mcfbench collect` then finds every cell of the matrix exactly once, each with its distance
#     to the reference cell, and the report was written, not marked incomplete;
#   - no temporary file is left.
#
# usage: test_slurm_live.sh MCFBENCH
#
# Needs root (slurmd starts the jobs; SlurmUser is root) and Debian's slurmctld, slurmd,
# slurm-client and munge (scripts/setup.sh installs them); elsewhere it exits 77, which ctest
# reports as skipped. A daemon that does not start, or a job that does not end in time, fails the
# test with the daemons' logs. Every wait polls the scheduler with a deadline; together the
# deadlines stay below the test's ctest TIMEOUT, so that the test ends by itself and its clean-up
# runs. The daemons are stopped through their pid files, and the folder removed, however the test
# ends.
set -u
mcfbench=${1:?usage: test_slurm_live.sh MCFBENCH}
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
config=$root/harness/configs/model_error.json
py=/usr/bin/python3

if [ "$(id -u)" != 0 ]; then
  echo "SKIP: a local Slurm needs root (slurmd starts the jobs)"
  exit 77
fi
# Only this test's cluster: nothing from a surrounding job or shell (SBATCH_PARTITION, ...).
for v in $(compgen -e); do
  case $v in SLURM_* | SBATCH_* | SQUEUE_* | SINFO_* | SCANCEL_* | SACCT_*) unset "$v" ;; esac
done

start=$SECONDS
work=$(mktemp -d)
chmod 755 "$work" # munged wants every folder above its socket searchable by all
s=$work/slurm
mkdir -p "$s/state" "$s/spool"
export SLURM_CONF=$s/slurm.conf

show_logs() {
  for f in "$s"/*.log; do
    [ -f "$f" ] || continue
    echo "=== $f (last 40 lines)"
    tail -n 40 "$f"
  done
  if [ -d "${out:-}/slurm/logs" ]; then
    for f in "$out"/slurm/logs/*; do
      echo "=== $f"
      cat "$f"
    done
  fi
}
fail() {
  echo "FAIL: $*"
  show_logs
  exit 1
}
# Polls `COMMAND...` every 0.2 s until it succeeds; returns 1 once LIMIT seconds have passed.
wait_for() {
  local limit=$1
  shift
  local deadline=$((SECONDS + limit))
  until "$@"; do
    [ $SECONDS -lt $deadline ] || return 1
    sleep 0.2
  done
}
pid_of() { [ -s "$s/$1.pid" ] && cat "$s/$1.pid"; }
running() {
  local pid
  pid=$(pid_of "$1") && kill -0 "$pid" 2>/dev/null
}
stopped() { ! kill -0 "$1" 2>/dev/null; }
# Stops a daemon through its pid file: SIGTERM, then SIGKILL if it is still there after 10 s.
stop_daemon() {
  local pid
  pid=$(pid_of "$1") || return 0
  kill "$pid" 2>/dev/null || return 0
  wait_for 10 stopped "$pid" || kill -9 "$pid" 2>/dev/null
}
# Empty only when squeue answered: a failing squeue prints nothing too.
queue_empty() {
  local listed
  listed=$(squeue --noheader --format=%i 2>/dev/null) && [ -z "$listed" ]
}
cleanup() {
  # The jobs first: job steps outlive a stopped slurmd.
  if running slurmctld && ! queue_empty; then
    scancel $(squeue --noheader --format=%A) 2>/dev/null
    wait_for 30 queue_empty
  fi
  stop_daemon slurmd
  stop_daemon slurmctld
  stop_daemon munged
  rm -rf "$work"
}
trap cleanup EXIT

for program in munged slurmctld slurmd sbatch squeue scancel sinfo; do
  command -v "$program" >/dev/null ||
    fail "$program is not installed (scripts/setup.sh installs slurmctld, slurmd, slurm-client and munge)"
done

# --- The cluster ---
if command -v mungekey >/dev/null; then
  mungekey --create --keyfile="$s/munge.key" || fail "mungekey could not create a key"
else
  dd if=/dev/urandom of="$s/munge.key" bs=1024 count=1 status=none || fail "no munge key"
fi
chmod 400 "$s/munge.key"
munged --socket="$s/munge.sock" --key-file="$s/munge.key" --pid-file="$s/munged.pid" \
  --log-file="$s/munged.log" --seed-file="$s/munged.seed" || fail "munged did not start"
wait_for 30 test -S "$s/munge.sock" || fail "munged created no socket"

read -r ctld_port slurmd_port < <("$py" -c '
import socket
socks = [socket.socket() for _ in range(2)]
for sock in socks:
    sock.bind(("127.0.0.1", 0))
print(*[sock.getsockname()[1] for sock in socks])')
[ -n "${slurmd_port:-}" ] || fail "no free ports found"
cat >"$SLURM_CONF" <<EOF
ClusterName=mcfbench-test
SlurmctldHost=localhost
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$s/munge.sock
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$s/state
SlurmdSpoolDir=$s/spool
SlurmctldPidFile=$s/slurmctld.pid
SlurmdPidFile=$s/slurmd.pid
SlurmctldLogFile=$s/slurmctld.log
SlurmdLogFile=$s/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
MpiDefault=none
SwitchType=switch/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
ReturnToService=2
# Ended jobs stay listed (squeue --states=all) long enough for the checks below.
MinJobAge=3600
NodeName=localhost CPUs=$(nproc) State=UNKNOWN
PartitionName=test Nodes=localhost Default=YES MaxTime=INFINITE State=UP
EOF
slurmctld -f "$SLURM_CONF" || fail "slurmctld did not start"
slurmd -f "$SLURM_CONF" || fail "slurmd did not start"
node_idle() { [ "$(sinfo --noheader --format=%t 2>/dev/null)" = idle ]; }
wait_for 60 node_idle || fail "the node is not idle after 60 s: $(sinfo 2>&1)"
echo "cluster up after $((SECONDS - start)) s"

# --- Helpers on the study ---
out="$work/study results" # a space: every path in the batch scripts must be quoted
submit() { "$mcfbench" submit "$config" --quick --out "$out" --tasks 3 --time 10:00; }
field() { "$py" -c 'import json, sys; print(json.load(open(sys.argv[1]))[sys.argv[2]])' "$out/slurm/submitted.json" "$1"; }
state() { squeue --noheader --states=all --jobs="$1" --format=%T 2>/dev/null | head -n 1; }
gone() {
  local listed
  listed=$(squeue --noheader --jobs="$1" --format=%i 2>/dev/null) && [ -z "$listed" ]
}
# The cell results, their checksums (what a rerun of a cell would change).
checksums() { (cd "$out" && find . -maxdepth 1 -name '*.json' ! -name index.json -print0 | sort -z | xargs -0 -r sha256sum); }
cells=$("$mcfbench" expand "$config" --quick | sed -n 's/^# .*: \([0-9]*\) cells$/\1/p')
[ -n "$cells" ] || fail "cannot count the quick matrix's cells: $("$mcfbench" expand "$config" --quick 2>&1 | head -3)"

# --- First submission; one task cancelled while it runs ---
t=$SECONDS
submit >"$work/submit1.txt" 2>&1 || fail "submit: $(cat "$work/submit1.txt")"
cat "$work/submit1.txt"
array1=$(field array_job)
collect1=$(field collect_job)
[ "$(field array)" = 0-2 ] || fail "the first submission's array is not 0-2: $(field array)"
# While those jobs are queued a second submission is refused (what squeue lists, read for real).
if submit >"$work/early.txt" 2>&1; then fail "a submission while the first one's jobs are queued was accepted: $(cat "$work/early.txt")"; fi
grep -q "still queued or running" "$work/early.txt" || fail "the early second submission says: $(cat "$work/early.txt")"
[ "$(field array_job)" = "$array1" ] || fail "the refused submission changed $out/slurm/submitted.json"
# Shard 1 holds the longest cells of the quick matrix: seconds of work left when it is cancelled.
# Cancelled once its run has published its plan (before its first cell), not as soon as squeue
# says RUNNING: a cancel that reaches slurmd while it is still launching the batch script can
# leave the script running to its end (every cell written, the task listed as CANCELLED).
task_running() { [ "$(state "${array1}_1")" = RUNNING ]; }
task_planned() { compgen -G "$out/plans/*.shard-1-of-3.json" >/dev/null; }
wait_for 120 task_running || fail "task ${array1}_1 did not start within 120 s: $(squeue --states=all 2>&1)"
wait_for 60 task_planned || fail "task ${array1}_1 wrote no run plan within 60 s of starting: $(ls -R "$out" 2>&1)"
scancel "${array1}_1" || fail "scancel ${array1}_1"
wait_for 420 gone "$array1,$collect1" || fail "the first submission's jobs did not end within 420 s: $(squeue 2>&1)"
echo "first submission ended after $((SECONDS - t)) s"
squeue --states=all --format="%i %T %M"
[ "$(state "${array1}_1")" = CANCELLED ] ||
  fail "task ${array1}_1 is $(state "${array1}_1"), not CANCELLED: it ended before it could be cancelled"
for task in 0 2; do
  [ "$(state "${array1}_$task")" = COMPLETED ] || fail "task ${array1}_$task: $(state "${array1}_$task")"
done
[ "$(state "$collect1")" = FAILED ] || fail "the first collect job is $(state "$collect1"), not FAILED (cells are missing)"
log1="$out/slurm/logs/collect-$collect1.out"
grep -q "missing cells" "$log1" || fail "the first collect job's log names no missing cell"
grep -qF "To run them, submit again" "$log1" || fail "the first collect job's log says not how to go on"
[ -s "$out/report/index.md" ] || fail "the first collect job wrote no report"
grep -qi incomplete "$out/report/index.md" || fail "the report of the incomplete results is not marked incomplete"
checksums >"$work/finished_before.txt"

# --- Second submission: only the lost shard ---
t=$SECONDS
submit >"$work/submit2.txt" 2>&1 || fail "second submit: $(cat "$work/submit2.txt")"
cat "$work/submit2.txt"
array2=$(field array_job)
collect2=$(field collect_job)
[ "$(field array)" = 1 ] || fail "the second submission runs tasks $(field array), not only the cancelled task 1"
wait_for 420 gone "$array2,$collect2" || fail "the second submission's jobs did not end within 420 s: $(squeue 2>&1)"
echo "second submission ended after $((SECONDS - t)) s"
squeue --states=all --format="%i %T %M"
[ "$(state "${array2}_1")" = COMPLETED ] || fail "task ${array2}_1: $(state "${array2}_1")"
[ "$(state "$collect2")" = COMPLETED ] || fail "the second collect job: $(state "$collect2")"

# --- The results ---
checksums >"$work/finished_after.txt"
changed=$(join -j 2 -o 1.1,2.1,0 <(sort -k2 "$work/finished_before.txt") <(sort -k2 "$work/finished_after.txt") | awk '$1 != $2 {print $3}')
[ -z "$changed" ] || fail "cells finished by the first submission were written again: $changed"
"$mcfbench" collect "$out" >"$work/collect.txt" 2>&1 || fail "collect: $(cat "$work/collect.txt")"
cat "$work/collect.txt"
grep -q "$cells cells found of $cells, 0 missing, 0 duplicated, 0 errored" "$work/collect.txt" ||
  fail "collect does not find the $cells cells once each"
grep -q "lack their reference distance" "$work/collect.txt" && fail "cells lack their reference distance"
"$py" - "$out/index.json" "$cells" <<'PY' || fail "index.json does not hold every cell exactly once"
import json, sys
index = json.load(open(sys.argv[1]))
cells = sorted(f["index"] for f in index["files"])
assert cells == list(range(int(sys.argv[2]))), cells
assert all(f["status"] == "ok" for f in index["files"]), [f["status"] for f in index["files"]]
PY
[ -s "$out/report/index.md" ] || fail "no report: $out/report/index.md"
grep -qi incomplete "$out/report/index.md" && fail "the final report is marked incomplete"
left=$(find "$out" -name '*.tmp.*')
[ -z "$left" ] || fail "temporary files left: $left"
# --- A cell divided across MPI ranks: --nodes and the cells' ranks as each job's tasks ---
ranked="$work/ranked results"
cat >"$work/ranked.json" <<'JSON'
{"name": "ranked", "defaults": {"mesh": "sphere:vertices=3000", "solver.name": "multigrid",
  "dt": 1e-3, "steps": 2, "mpi_ranks": 2}}
JSON
t=$SECONDS
# sbatch passes the submitter's environment on: Open MPI's consent to run as root (CI is root).
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
"$mcfbench" submit "$work/ranked.json" --out "$ranked" --nodes 1 --time 10:00 >"$work/submit3.txt" 2>&1 ||
  fail "submit of the ranked cell: $(cat "$work/submit3.txt")"
grep -q '^#SBATCH --ntasks=2$' "$ranked/slurm/run.sbatch" || fail "no --ntasks=2 in the array script"
grep -q '^#SBATCH --nodes=1$' "$ranked/slurm/run.sbatch" || fail "no --nodes=1 in the array script"
array3=$("$py" -c 'import json, sys; print(json.load(open(sys.argv[1]))["array_job"])' "$ranked/slurm/submitted.json")
collect3=$("$py" -c 'import json, sys; print(json.load(open(sys.argv[1]))["collect_job"])' "$ranked/slurm/submitted.json")
wait_for 300 gone "$array3,$collect3" || fail "the ranked cell's jobs did not end within 300 s: $(squeue 2>&1)"
cat "$ranked"/slurm/logs/*.out "$ranked"/slurm/logs/*.err 2>/dev/null | tail -30
"$py" - "$ranked" <<'PY' || fail "the ranked cell's result"
import glob, json, sys
cells = [json.load(open(f)) for f in glob.glob(sys.argv[1] + "/*.json") if not f.endswith("index.json")]
cells = [c for c in cells if "cell" in c]
assert len(cells) == 1 and cells[0]["status"] == "ok", [c.get("status") for c in cells]
d = cells[0]["distribution"]
assert d["ranks"] == 2 and len(d["owned_vertices"]) == 2, d
print("the ranked cell ran on %d ranks in its Slurm job: owned %s" % (d["ranks"], d["owned_vertices"]))
PY
echo "ranked cell done after $((SECONDS - t)) s"
echo "slurm live test passed in $((SECONDS - start)) s"
