#!/usr/bin/python3
"""A stand-in for scripts/history_runner.sh in the history tests: `fake_bench_runner.py CONFIG
OUT`, run in a worktree of a scratch repository. Writes cell results of two cells, "slowed"
(its step time is the number in the worktree's speed.txt) and "steady" (always 1), with
$MCFBENCH_HISTORY_REPETITIONS repetitions and a deterministic +-1% jitter drawn from the commit
and repetition, and appends the commit to $FAKE_RUNNER_LOG, so a test counts the runs. A commit
whose tree holds broken.txt fails as one that does not build would (exit 3, after logging the
run); with $FAKE_RUNNER_CONTENDED=1 every repetition says it shared the machine; with
$FAKE_RUNNER_HEAD_THREADS=N the head side of `history ab` ($MCFBENCH_HISTORY_SIDE) ran N threads;
with $FAKE_RUNNER_PHASE=update the slowdown is in the steps' update phase alone.
For a micro-benchmark config (a "micro" key, as scripts/history_micro_runner.sh takes) it leaves
mcfbench_micro's JSON as OUT/micro.json instead: BM_Slowed (speed.txt, in ms) and BM_Steady."""

import hashlib
import json
import os
import sys

config, out = sys.argv[1], sys.argv[2]
commit = os.environ["MCFBENCH_HISTORY_COMMIT"]
reps = int(os.environ.get("MCFBENCH_HISTORY_REPETITIONS", "1"))
speed = float(open("speed.txt").read())
with open(os.environ["FAKE_RUNNER_LOG"], "a") as f:
    f.write(commit + "\n")
if os.path.exists("broken.txt"):
    print("fake_bench_runner: %s does not build" % commit[:12], file=sys.stderr)
    sys.exit(3)
contended = os.environ.get("FAKE_RUNNER_CONTENDED") == "1"
# This computer's CPU model and core count, as mcfbench records them, so that the history finds
# its machine folder before it runs anything.
cpu = next((line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo")
            if line.startswith("model name")), "unknown")
threads = 2
if os.environ.get("MCFBENCH_HISTORY_SIDE") == "head" and os.environ.get("FAKE_RUNNER_HEAD_THREADS"):
    threads = int(os.environ["FAKE_RUNNER_HEAD_THREADS"])
env = {"commit": commit[:12], "cpu": cpu, "cores": os.cpu_count(), "threads": threads,
       "blas_threads": 2, "build": {"type": "Release", "compiler": "fake"}, "hostname": "h"}
if "micro" in json.load(open(config)):
    rows = []
    for name, base in (("BM_Slowed", speed), ("BM_Steady", 1.0)):
        for r in range(reps):
            h = int(hashlib.sha1(("%s/%s/%d" % (commit, name, r)).encode()).hexdigest()[:8], 16)
            rows.append({"name": name, "run_name": name, "run_type": "iteration",
                         "repetitions": reps, "repetition_index": r, "iterations": 5,
                         "real_time": base * (1 + 0.02 * (h / 0xFFFFFFFF - 0.5)),
                         "cpu_time": base, "time_unit": "ms"})
    with open(os.path.join(out, "micro.json"), "w") as f:
        json.dump({"context": {"mcfbench_environment": json.dumps(env)}, "benchmarks": rows}, f)
    sys.exit(0)
for cell, base in (("slowed", speed), ("steady", 1.0)):
    for r in range(reps):
        h = int(hashlib.sha1(("%s/%s/%d" % (commit, cell, r)).encode()).hexdigest()[:8], 16)
        v = base * (1 + 0.02 * (h / 0xFFFFFFFF - 0.5))
        # The phases: an update of a fifth of the step and a solve of the rest; with
        # $FAKE_RUNNER_PHASE=update only the update is slowed (the step by a fifth as much).
        if os.environ.get("FAKE_RUNNER_PHASE") == "update":
            update, solve = 0.2 * v, 0.8 * (v / base)
        else:
            update, solve = 0.2 * v, 0.8 * v
        v = update + solve
        steps = [{"step": 1, "seconds": {"total": 3 * v, "update": 3 * update, "solve": 3 * solve}}]
        steps += [{"step": s, "seconds": {"total": v, "update": update, "solve": solve}}
                  for s in range(2, 5)]
        res = {"schema": 1, "status": "ok", "stop": {"step": 4, "reason": "completed"},
               "environment": env,
               "cell": {"key": "%s-%d" % (cell, r), "config_key": cell, "repetition": r,
                        "study": "fake", "assignment": {"solver.name": cell}},
               "steps": steps, "timing": {"step_median_seconds": v},
               "contention": {"contended": contended}}
        with open(os.path.join(out, "%s-%d.json" % (cell, r)), "w") as f:
            json.dump(res, f)
