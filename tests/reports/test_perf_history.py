#!/usr/bin/python3
"""Performance history (reports/perf_history.py, ctest `history`), all on synthetic data:

- the step detector finds a 20% step under 5% noise at its index, and raises an alarm on fewer
  than 5 of 100 flat noisy series with outliers (seeded, so the outcome is fixed);
- on a scratch git repository of 16 commits with a 30% slowdown planted in one, run through a
  stand-in runner (tests/reports/fake_bench_runner.py) instead of building mcfbench:
  `bisect` names the planted commit within log2(16) + 1 = 5 runs, `run --last 16` stores one
  entry per commit in git order (also when stored out of order), `detect` reports the step at
  the planted commit and nowhere else (with every other commit stored, it points `bisect` at the
  gap, which then runs one commit), `publish` lists it in its regressions, and `ab` with
  `mcfbench compare` (given with --mcfbench) fails on the slowdown and passes without one.

usage: test_perf_history.py [--mcfbench BIN] [--keep DIR]
"""

import argparse
import json
import math
import os
import random
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "reports"))
import perf_history as ph  # noqa: E402

TOOL = [sys.executable, os.path.join(ROOT, "reports", "perf_history.py")]
RUNNER = "%s %s" % (sys.executable, os.path.join(HERE, "fake_bench_runner.py"))
PLANTED = 9  # the commit (0-based) whose speed.txt says 1.3 instead of 1.0
failures = []


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        failures.append(what)


def test_detector():
    rng = random.Random(20261127)
    exact, near = 0, 0
    for _ in range(100):
        v = [(1.0 if i < 15 else 1.2) * (1 + rng.gauss(0, 0.05)) for i in range(30)]
        s = ph.detect_steps(v)
        exact += len(s) == 1 and s[0]["index"] == 15
        near += len(s) == 1 and abs(s[0]["index"] - 15) <= 2 and s[0]["ratio"] > 1.1
    # Noise of 5% makes a point next to the step look like the other level now and then, which
    # no detector can tell apart; found every time, at the exact commit in most.
    check(exact >= 85, "20%% step under 5%% noise: at the exact index in %d of 100" % exact)
    check(near == 100, "20%% step under 5%% noise: one step within 2 commits in %d of 100" % near)
    alarms = 0
    for k in range(100):
        v = [1 + rng.gauss(0, 0.05) for _ in range(30)]
        if k % 3 == 0:
            v[rng.randrange(30)] *= 1.5  # a lone outlier: one noisy run, not a step
        alarms += bool(ph.detect_steps(v))
    check(alarms < 5, "flat series with 5%% noise and outliers: %d of 100 alarms" % alarms)
    check(not ph.detect_steps([1.0] * 20), "a constant series has no step")


def test_contended_repetitions(work):
    """A commit's median leaves out repetitions that shared the machine while one ran alone."""
    folder = os.path.join(work, "contended")
    os.makedirs(folder)
    for r, (v, contended) in enumerate([(10.0, True), (1.0, False), (12.0, True)]):
        with open(os.path.join(folder, "c%d.json" % r), "w") as f:
            json.dump({"status": "ok", "environment": {"commit": "abc", "cpu": "X"},
                       "cell": {"config_key": "k", "repetition": r, "assignment": {"a": 1}},
                       "timing": {"step_median_seconds": v},
                       "contention": {"contended": contended}}, f)
    e = ph.store_result_set(os.path.join(work, "store_c"), "c", folder,
                            {"commit": "abc", "date": "2026-01-01", "parents": []})
    b = e["benchmarks"]["a=1"]
    check(b["median"] == 1.0 and b["samples"] == [10.0, 1.0, 12.0] and
          b["contended"] == [True, False, True], "contended repetitions are kept, not counted")


# The scratch repository ignores the user's and the system's git configuration (signing,
# hooks, default branch), so its commits are the same everywhere.
GIT_ENV = dict(os.environ, GIT_CONFIG_GLOBAL=os.devnull, GIT_CONFIG_NOSYSTEM="1")


def git(repo, *args):
    return subprocess.run(["git", "-C", repo] + list(args), check=True, capture_output=True,
                          text=True, env=GIT_ENV).stdout.strip()


def scratch_repo(path, broken=()):
    """16 commits; commit PLANTED makes the 'slowed' benchmark 30% slower. Dates increase. The
    commits numbered in `broken` hold broken.txt: the stand-in runner fails on them as on a
    commit that does not build."""
    os.makedirs(path)
    git(path, "init", "-q", "-b", "main")
    commits = []
    for i in range(16):
        with open(os.path.join(path, "speed.txt"), "w") as f:
            f.write("1.3" if i >= PLANTED else "1.0")
        with open(os.path.join(path, "notes.txt"), "a") as f:
            f.write("change %d\n" % i)
        if i in broken:
            open(os.path.join(path, "broken.txt"), "w").close()
        elif os.path.exists(os.path.join(path, "broken.txt")):
            os.remove(os.path.join(path, "broken.txt"))
        git(path, "add", "-A")
        env = dict(GIT_ENV, GIT_AUTHOR_DATE="2026-01-%02dT12:00:00Z" % (i + 1),
                   GIT_COMMITTER_DATE="2026-01-%02dT12:00:00Z" % (i + 1),
                   GIT_AUTHOR_NAME="t", GIT_AUTHOR_EMAIL="t@t", GIT_COMMITTER_NAME="t",
                   GIT_COMMITTER_EMAIL="t@t")
        subprocess.run(["git", "-C", path, "commit", "-q", "-m", "commit %d" % i], check=True,
                       env=env)
        commits.append(git(path, "rev-parse", "HEAD"))
    return commits


def tool(work, *args, expect=0, env=None):
    env = dict(os.environ, FAKE_RUNNER_LOG=os.path.join(work, "runs.log"), **(env or {}))
    r = subprocess.run(TOOL + list(args), cwd=work, env=env, capture_output=True, text=True)
    if r.returncode != expect:
        print(r.stdout + r.stderr)
    check(r.returncode == expect, "history %s: exit %d (expected %d)" % (args[0], r.returncode,
                                                                          expect))
    return r


def runs(work):
    path = os.path.join(work, "runs.log")
    n = len(open(path).read().split()) if os.path.exists(path) else 0
    if os.path.exists(path):
        os.remove(path)
    return n


def test_repository(work, mcfbench):
    repo = os.path.join(work, "repo")
    commits = scratch_repo(repo)
    config = os.path.join(work, "fake.json")
    with open(config, "w") as f:
        json.dump({"name": "fake"}, f)
    common = ["--repo", repo, "--runner", RUNNER]

    # Bisect: the good end and one commit per halving of the 15 candidates.
    r = tool(work, "bisect", config, "--good", commits[0], "--bad", commits[-1], "--store",
             "store_bisect", "--repetitions", "3", "--json", "bisect.json", *common)
    out = json.load(open(os.path.join(work, "bisect.json")))
    n = runs(work)
    check(out["first_bad"] == commits[PLANTED], "bisect names the planted commit")
    check(n <= 5 and out["runs"] == n, "bisect ran %d commits (at most 5)" % n)
    # A second bisect over the same store runs nothing it has measured before.
    tool(work, "bisect", config, "--good", commits[0], "--bad", commits[-1], "--store",
         "store_bisect", "--repetitions", "3", *common)
    check(runs(work) == 0, "a repeated bisect runs nothing (the store's machine of this CPU)")

    # Run the last 16 commits into a store; entries carry date and parents.
    tool(work, "run", config, "--last", "16", "--store", "store", "--repetitions", "3", *common)
    check(runs(work) == 16, "run --last 16 ran 16 commits")
    tool(work, "run", config, commits[3] + ".." + commits[5], "--store", "store", *common,
         "--machine", os.listdir(os.path.join(work, "store"))[0])
    check(runs(work) == 0, "run A..B of stored commits runs nothing")
    tool(work, "run", config, "--last", "3", "--store", "store", *common)
    check(runs(work) == 0, "nor does run --last N without --machine")
    # A commit that does not run is skipped, the others stored: exit 1 naming it.
    with open(os.path.join(work, "failing_runner.sh"), "w") as f:
        f.write('[ "$MCFBENCH_HISTORY_COMMIT" = %s ] && exit 3\nexec %s "$@"\n' %
                (commits[2], RUNNER))
    r = tool(work, "run", config, commits[1] + ".." + commits[3], "--store", "store_gap",
             "--repo", repo, "--runner", "bash " + os.path.join(work, "failing_runner.sh"),
             expect=1)
    runs(work)
    gap = list(ph.load_store(os.path.join(work, "store_gap")).values())[0]
    check([e["commit"] for e in gap] == [commits[1], commits[3]] and commits[2][:12] in r.stdout,
          "a commit whose runner fails is skipped and named")
    series = ph.load_store(os.path.join(work, "store"))
    check(len(series) == 1, "one (machine, config) series")
    entries = list(series.values())[0]
    check([e["commit"] for e in entries] == commits, "the series is in git order")
    check(entries[5]["parents"] == [commits[4]], "an entry records its parents")
    # Git order, not file or date order: a commit dated before its parent stays after it.
    e = dict(entries[7], date="2025-01-01T00:00:00Z")
    shuffled = [e] + entries[:7] + entries[8:]
    random.Random(1).shuffle(shuffled)
    check([x["commit"] for x in ph.git_order(shuffled)] == commits,
          "git order survives shuffled entries and a skewed date")

    tool(work, "detect", "--store", "store", "--json", "steps.json")
    steps = json.load(open(os.path.join(work, "steps.json")))
    check(len(steps) == 1, "detect finds one step (found %d)" % len(steps))
    if steps:
        s = steps[0]
        check(s["commit"] == commits[PLANTED] and s["benchmark"] == "solver.name=slowed",
              "the step is at the planted commit, on the slowed benchmark")
        check(abs(s["ratio"] - 1.3) < 0.03 and s["confidence"] > 0.99,
              "its size is 1.3 (%.3f), its confidence high (%.4f)" % (s["ratio"],
                                                                     s["confidence"]))
    tool(work, "detect", "--store", "store", "--fail-on-regression", expect=1)

    # Every other commit measured: the step lies between two measured commits, detect says how
    # to bisect it, and the bisect that reuses the store runs the one commit in between.
    for c in commits[::2]:
        tool(work, "run", config, c, "--store", "store_sparse", "--repetitions", "3", *common)
    runs(work)
    # 5 commits before the step and 3 after: the U test's p is 0.037 at best, so alpha 0.05.
    r = tool(work, "detect", "--store", "store_sparse", "--alpha", "0.05")
    hint = "--good %s --bad %s" % (commits[PLANTED - 1][:12], commits[PLANTED + 1][:12])
    check(hint in r.stdout, "detect suggests bisecting between the measured neighbours")
    r = tool(work, "bisect", config, "--good", commits[PLANTED - 1][:12], "--bad",
             commits[PLANTED + 1][:12], "--store", "store_sparse", "--repetitions", "3", *common)
    check(runs(work) == 1 and commits[PLANTED] in r.stdout,
          "that bisect runs one commit and names the planted one")

    tool(work, "publish", os.path.join(work, "site"), "--store", "store")
    page = open(os.path.join(work, "site", "index.html")).read()
    check(page.count('<svg class="chart"') == 2, "the page has one chart per benchmark")
    check(commits[PLANTED][:12] in page.split('id="regressions"')[1].split("</table>")[0],
          "the regressions list names the planted commit")
    check("http://" not in page.replace("http://www.w3.org/2000/svg", "") and
          "https://" not in page, "the page loads nothing from the network")

    # The gate: base and head alternated, compared by mcfbench compare.
    if mcfbench:
        cmp = ["--compare", "%s compare" % mcfbench]
        tool(work, "ab", config, commits[0], commits[-1], "--rounds", "5", "--out", "ab_slow",
             *common, *cmp, expect=1)
        check(runs(work) == 10, "ab ran each side once per round")
        tool(work, "ab", config, commits[PLANTED], commits[-1], "--rounds", "5", "--out",
             "ab_same", *common, *cmp, expect=0)
        runs(work)
        gate = subprocess.run(
            ["bash", os.path.join(ROOT, "scripts", "perf_gate.sh"), config, commits[0],
             commits[-1]], cwd=repo, capture_output=True, text=True,
            env=dict(os.environ, FAKE_RUNNER_LOG=os.path.join(work, "runs.log"),
                     MCFBENCH_GATE_RUNNER=RUNNER, MCFBENCH_GATE_COMPARE="%s compare" % mcfbench,
                     MCFBENCH_GATE_OUT=os.path.join(work, "gate"), MCFBENCH_GATE_REPO=repo))
        check(gate.returncode == 1 and "slower" in gate.stdout,
              "perf_gate.sh fails on the slowdown (exit %d)" % gate.returncode)
        if gate.returncode != 1:
            print(gate.stdout + gate.stderr)
        # A slowdown of one phase (the update, a fifth of the step: +6% of the step) passes a
        # gate on the step alone and fails one that compares the phases too.
        tool(work, "ab", config, commits[0], commits[-1], "--rounds", "5", "--out", "ab_phase",
             *common, *cmp, expect=0, env={"FAKE_RUNNER_PHASE": "update"})
        r = tool(work, "ab", config, commits[0], commits[-1], "--rounds", "5", "--out",
                 "ab_phase_metrics", *common, *cmp, "--metric", "seconds.total", "--metric",
                 "seconds.update", expect=1, env={"FAKE_RUNNER_PHASE": "update"})
        check("## seconds.update" in r.stdout and
              "slower" in r.stdout.split("## seconds.update")[1],
              "ab with --metric seconds.update finds the slower update")
        runs(work)
        # Repetitions that shared the machine make the answer inconclusive, not a regression.
        r = tool(work, "ab", config, commits[0], commits[-1], "--rounds", "5", "--out",
                 "ab_contended", *common, *cmp, expect=3, env={"FAKE_RUNNER_CONTENDED": "1"})
        check("INCONCLUSIVE" in r.stdout, "ab on a contended machine says inconclusive")
        r = tool(work, "ab", config, commits[PLANTED], commits[-1], "--rounds", "5", "--out",
                 "ab_contended_same", *common, *cmp, expect=3,
                 env={"FAKE_RUNNER_CONTENDED": "1"})
        check("INCONCLUSIVE" in r.stdout, "also where the timings agree")
        # Sides that ran differently (threads, machine, build): an error, never a regression.
        r = tool(work, "ab", config, commits[0], commits[-1], "--rounds", "5", "--out",
                 "ab_threads", *common, *cmp, expect=2, env={"FAKE_RUNNER_HEAD_THREADS": "1"})
        check("without a verdict" in r.stderr and "threads" in r.stderr,
              "ab of sides with different thread counts is an error (exit 2), not a regression")
        runs(work)


def test_bisect_skips(work):
    """Commits that do not build are skipped as `git bisect skip` skips them: away from the step
    the planted commit is still named; when the planted commit itself does not build, the answer
    is the range of it and the next (exit 3), not a guess."""
    config = os.path.join(work, "fake.json")
    for broken, expect in (({12}, 0), ({PLANTED}, 3)):
        repo = os.path.join(work, "repo_broken_%d" % min(broken))
        commits = scratch_repo(repo, broken)
        out = os.path.join(work, "bisect_broken_%d.json" % min(broken))
        r = tool(work, "bisect", config, "--good", commits[0], "--bad", commits[-1], "--store",
                 "store_broken_%d" % min(broken), "--repetitions", "3", "--json", out,
                 "--repo", repo, "--runner", RUNNER, expect=expect)
        o = json.load(open(out))
        n = runs(work)
        check(o["skipped"] == [commits[i] for i in sorted(broken)],
              "bisect with commit %s not building skips it" % sorted(broken))
        if expect == 0:
            check(o["first_bad"] == commits[PLANTED] and n == 6,
                  "one commit skipped away from the step: the planted commit named in 6 runs "
                  "(%d)" % n)
        else:
            check(o["first_bad"] is None and o["candidates"] == commits[PLANTED:PLANTED + 2] and
                  all(c in r.stdout for c in commits[PLANTED:PLANTED + 2]),
                  "the planted commit not building: the answer is it and the next, exit 3")


def micro_json(path, commit, benchmarks, context=True, planted=0):
    """A Google Benchmark JSON file as mcfbench_micro writes it: three repetitions of each
    benchmark (times in ms) with their aggregates, and the mcfbench environment in its context."""
    env = {"commit": commit[:12], "cpu": "Synthetic CPU", "cores": 2, "threads": 2,
           "blas_threads": 2, "hostname": "h", "build": {"type": "Release"}}
    if planted:
        env["planted_slowdown"] = planted
    rows = []
    for name, ms in benchmarks.items():
        for r in range(3):
            rows.append({"name": name, "run_name": name, "run_type": "iteration",
                         "repetitions": 3, "repetition_index": r, "iterations": 10,
                         "real_time": ms * (1 + 0.01 * (r - 1)), "cpu_time": ms,
                         "time_unit": "ms"})
        rows.append({"name": name + "_mean", "run_name": name, "run_type": "aggregate",
                     "aggregate_name": "mean", "real_time": 99 * ms, "time_unit": "ms"})
    ctx = {"host_name": "h", "num_cpus": 2}
    if context:
        ctx["mcfbench_environment"] = json.dumps(env)
    with open(path, "w") as f:
        json.dump({"context": ctx, "benchmarks": rows}, f)


def test_micro(work):
    """mcfbench_micro's JSON (benchmarks/run_micro.sh) stored by `add`: one series per
    benchmark keyed by the machine in its context, samples are repetitions in seconds,
    aggregates left out, a commit's earlier benchmarks kept when another filter ran, and
    `detect` finds a planted step in it."""
    repo = os.path.join(work, "repo")  # test_repository's scratch repository
    commits = git(repo, "rev-list", "--reverse", "HEAD").split()
    for i, c in enumerate(commits[:8]):
        path = os.path.join(work, "micro_%d.json" % i)
        micro_json(path, c, {"BM_Step/8": 2.0 * (1.3 if i >= 4 else 1.0), "BM_Update": 1.0})
        tool(work, "add", "micro", path, "--store", "store_micro", "--repo", repo)
    path = os.path.join(work, "micro_extra.json")
    micro_json(path, commits[7], {"BM_Other": 5.0})
    tool(work, "add", "micro", path, "--store", "store_micro", "--repo", repo)
    series = ph.load_store(os.path.join(work, "store_micro"))
    check(list(k[1] for k in series) == ["micro"] and
          list(series.values())[0][0]["machine"].startswith("Synthetic-CPU-2c-2t-"),
          "micro results form the series (machine, micro)")
    entries = list(series.values())[0]
    b = entries[0]["benchmarks"]["BM_Step/8"]
    check([round(v, 9) for v in b["samples"]] == [0.00198, 0.002, 0.00202] and
          abs(b["median"] - 0.002) < 1e-12,
          "samples are the repetitions in seconds, aggregates left out")
    check(sorted(entries[-1]["benchmarks"]) == ["BM_Other", "BM_Step/8", "BM_Update"],
          "a second file of the same commit adds its benchmarks to the entry")
    check([e["commit"] for e in entries] == commits[:8], "micro entries in git order")
    tool(work, "detect", "--store", "store_micro", "--json", "micro_steps.json", "--alpha", "0.05")
    steps = json.load(open(os.path.join(work, "micro_steps.json")))
    check([(s["benchmark"], s["commit"]) for s in steps] == [("BM_Step/8", commits[4])],
          "detect finds the micro step at its commit")
    # `run` over commits with a micro-benchmark config: the runner's OUT/micro.json is stored
    # one benchmark per run name, and `detect` finds the planted commit.
    config = os.path.join(work, "micro_fake.json")
    with open(config, "w") as f:
        json.dump({"micro": {"benchmark_filter": "BM_"}}, f)
    tool(work, "run", config, "--last", "16", "--store", "store_micro_run", "--repetitions", "3",
         "--repo", repo, "--runner", RUNNER)
    check(runs(work) == 16, "run --last 16 of a micro config ran 16 commits")
    series = ph.load_store(os.path.join(work, "store_micro_run"))
    entries = series.get((list(series)[0][0], "micro_fake"), []) if series else []
    check(len(entries) == 16 and
          sorted(entries[0]["benchmarks"]) == ["BM_Slowed", "BM_Steady"] and
          len(entries[0]["benchmarks"]["BM_Slowed"]["samples"]) == 3 and
          entries[0]["metric"] == "real_time",
          "a micro config's runs are stored as mcfbench_micro's benchmarks, a sample a repetition")
    tool(work, "detect", "--store", "store_micro_run", "--json", "micro_run_steps.json")
    steps = json.load(open(os.path.join(work, "micro_run_steps.json")))
    check([(s["benchmark"], s["commit"]) for s in steps] == [("BM_Slowed", commits[PLANTED])],
          "detect finds the planted commit in a micro config's run")
    r = tool(work, "ab", config, commits[0], commits[1], "--out", "ab_micro", "--repo", repo,
             expect=2)
    check("compare.py" in r.stderr, "ab refuses a micro config, naming what compares those")
    micro_json(path, commits[3], {"BM_Step/8": 1.0}, planted=0.3)
    r = tool(work, "add", "micro", path, "--store", "store_micro", "--repo", repo, expect=2)
    check("planted slowdown" in r.stderr, "a run with a planted slowdown is not stored")
    micro_json(path, commits[3], {"BM_Step/8": 1.0}, context=False)
    r = tool(work, "add", "micro", path, "--store", "store_micro", "--repo", repo, expect=2)
    check("micro_extra.json" in r.stderr and "mcfbench_environment" in r.stderr,
          "a file without the machine is refused, naming it")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--mcfbench", default="")
    ap.add_argument("--keep", default="")
    a = ap.parse_args()
    a.mcfbench = os.path.abspath(a.mcfbench) if a.mcfbench else ""
    test_detector()
    work = a.keep or tempfile.mkdtemp(prefix="test_perf_history-")
    if a.keep:
        shutil.rmtree(work, ignore_errors=True)
        os.makedirs(work)
    try:
        test_contended_repetitions(work)
        test_repository(work, a.mcfbench)
        test_bisect_skips(work)
        test_micro(work)
    finally:
        if not a.keep:
            shutil.rmtree(work, ignore_errors=True)
    print("%d failures" % len(failures))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
