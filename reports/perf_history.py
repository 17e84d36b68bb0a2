#!/usr/bin/python3
"""Performance history: a store of result sets per machine and commit, runs over commit ranges,
step detection, bisection and a static dashboard.

usage: /usr/bin/python3 reports/perf_history.py COMMAND ...   (scripts/history.sh wraps it)

  run CONFIG (A..B|C|--last N)   build and run the commits, store each result set
  add CONFIG RESULTS             store a result set measured elsewhere (`mcfbench run` output,
                                 or mcfbench_micro's JSON: benchmarks/run_micro.sh does this)
  detect                         step changes per (benchmark, machine) series
  bisect CONFIG --good A --bad B the first commit of A..B that is slower than A
  ab CONFIG BASE HEAD --out DIR  BASE and HEAD alternated over rounds, then `mcfbench compare`
  publish OUT                    OUT/index.html: charts, steps, regressions (offline)

Every command takes --store DIR (default data/history) and --repo DIR (default: the git
repository of the current folder). `COMMAND --help` lists the rest.

Store layout: STORE/<machine>/machine.json (the identity: cpu, cores, threads, blas_threads,
build, libraries), STORE/<machine>/<config>/<commit>.json (one entry: commit, its date and
parents, the samples of each benchmark) and STORE/<machine>/<config>/<commit>/ (the result set
itself, readable by `mcfbench compare`). A benchmark's sample is one repetition's median step
after the first (the cell's timing.step_median_seconds), so a commit has as many samples as
repetitions. Series are ordered by git (parents, then commit date), never by arrival.

The runner of a commit is pluggable (--runner CMD): it is run as `CMD CONFIG OUT` in a git
worktree checked out at the commit, with MCFBENCH_HISTORY_COMMIT (40 hex),
MCFBENCH_HISTORY_REPETITIONS and MCFBENCH_HISTORY_SIDE (base or head under `ab`, else empty)
set, and must leave the cell results (JSON files with "cell",
"environment" and "steps" or "timing") in OUT. The default, scripts/history_runner.sh, builds the
commit (a build folder cached per commit) and runs the config's --quick variant.
"""

import argparse
import hashlib
import html
import json
import math
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_RUNNER = os.path.join(ROOT, "scripts", "history_runner.sh")
# The runner of micro-benchmark configs (a JSON object with a "micro" key): it leaves
# mcfbench_micro's JSON as OUT/micro.json.
MICRO_RUNNER = os.path.join(ROOT, "scripts", "history_micro_runner.sh")
IDENTITY_KEYS = ("cpu", "cores", "threads", "blas_threads", "build", "libraries")


def fail(msg):
    print("history: " + msg, file=sys.stderr)
    sys.exit(2)


# ----------------------------------------------------------------------------- statistics


def median(v):
    s = sorted(v)
    n = len(s)
    if n == 0:
        return float("nan")
    return s[n // 2] if n % 2 else 0.5 * (s[n // 2 - 1] + s[n // 2])


def mann_whitney_p(a, b):
    """Two-sided p of the U test (normal approximation, tie and continuity corrected), as
    harness/compare.cpp computes it; 1 when either side is empty or everything ties."""
    n1, n2 = len(a), len(b)
    if n1 == 0 or n2 == 0:
        return 1.0
    allv = sorted([(x, 0) for x in a] + [(x, 1) for x in b])
    rank_a, ties, i = 0.0, 0.0, 0
    while i < len(allv):
        j = i
        while j < len(allv) and allv[j][0] == allv[i][0]:
            j += 1
        t, mid = j - i, 0.5 * (i + 1 + j)
        ties += t ** 3 - t
        rank_a += mid * sum(1 for k in range(i, j) if allv[k][1] == 0)
        i = j
    n = n1 + n2
    u = rank_a - n1 * (n1 + 1) / 2
    var = n1 * n2 / 12 * ((n + 1) - ties / (n * (n - 1)))
    if var <= 0:
        return 1.0
    z = max(0.0, abs(u - n1 * n2 / 2) - 0.5) / math.sqrt(var)
    return math.erfc(z / math.sqrt(2))


def noise_scale(x):
    """Robust standard deviation of a series around its levels: the median absolute difference
    of neighbours (a step moves one difference only), scaled for a normal law."""
    if len(x) < 3:
        return 0.0
    d = [abs(x[i] - x[i - 1]) for i in range(1, len(x))]
    return 1.4826 * median(d) / math.sqrt(2)


def l1_partition(x, penalty):
    """Change points (start indices of new segments) of the piecewise-constant fit that
    minimises sum |x - segment median| + penalty per segment (optimal partitioning): absolute
    deviations leave a lone outlier cheaper to keep than to cut out."""
    n = len(x)
    cost = [[0.0] * (n + 1) for _ in range(n + 1)]
    for i in range(n):
        for j in range(i + 1, n + 1):
            m = median(x[i:j])
            cost[i][j] = sum(abs(v - m) for v in x[i:j])
    best = [0.0] + [math.inf] * n
    last = [0] * (n + 1)
    for j in range(1, n + 1):
        for i in range(j):
            c = best[i] + cost[i][j] + penalty
            if c < best[j]:
                best[j], last[j] = c, i
    cps, j = [], n
    while j > 0:
        if last[j] > 0:
            cps.append(last[j])
        j = last[j]
    return sorted(cps)


def detect_steps(values, threshold=0.1, alpha=0.01, min_run=2):
    """Steps of a series of per-commit medians `values` (in git order).

    A candidate from the L1 fit of log(values) is kept when the levels on either side differ
    by more than `threshold` (relative), each side has at least `min_run` commits, and the
    U test of the two sides' commit medians gives p < alpha; the weakest failing candidate is
    dropped and the others re-tested until all pass. Commit medians, not the repetitions, are
    the test's samples: repetitions of one commit ran back to back and share a noisy spell.
    Returns [{index, before, after, ratio, p, confidence}] with `index` the first commit of
    the new level."""
    x = [math.log(v) for v in values if v > 0]
    if len(x) != len(values) or len(x) < 2 * min_run:
        return []
    sigma = max(noise_scale(x), 1e-3)
    cps = l1_partition(x, 2.0 * sigma * math.log(len(x)))
    while True:
        bounds = [0] + cps + [len(x)]
        worst, worst_p, steps = None, -1.0, []
        for k, cp in enumerate(cps):
            left, right = x[bounds[k]:cp], x[cp:bounds[k + 2]]
            p = mann_whitney_p(left, right)
            ratio = math.exp(median(right) - median(left))
            ok = (min(len(left), len(right)) >= min_run and p < alpha and
                  (ratio > 1 + threshold or ratio < 1 / (1 + threshold)))
            if not ok and p > worst_p:
                worst, worst_p = k, p
            steps.append({"index": cp, "before": math.exp(median(left)),
                          "after": math.exp(median(right)), "ratio": ratio, "p": p,
                          "confidence": 1 - p})
        if worst is None:
            return steps
        del cps[worst]


# ----------------------------------------------------------------------------- git


def git(repo, *args):
    return subprocess.run(["git", "-C", repo] + list(args), check=True, capture_output=True,
                          text=True).stdout.strip()


def commit_info(repo, rev):
    out = git(repo, "show", "-s", "--format=%H%n%cI%n%P%n%s", rev).split("\n")
    return {"commit": out[0], "date": out[1], "parents": out[2].split(), "subject": out[3]}


def commit_range(repo, spec):
    """The commits of A..B on B's first-parent line, oldest first."""
    return git(repo, "rev-list", "--first-parent", "--reverse", spec).split()


# ----------------------------------------------------------------------------- the store


def machine_identity(result):
    env = result.get("environment") or {}
    return {k: env[k] for k in IDENTITY_KEYS if k in env}


def machine_id(identity):
    """A folder name: the CPU model, cores and threads readable, the whole identity hashed."""
    cpu = re.sub(r"[^A-Za-z0-9]+", "-", str(identity.get("cpu", "unknown"))).strip("-")[:32]
    h = hashlib.sha1(json.dumps(identity, sort_keys=True).encode()).hexdigest()[:8]
    return "%s-%sc-%st-%s" % (cpu, identity.get("cores", "x"), identity.get("threads", "x"), h)


def cell_label(cell):
    a = cell.get("assignment") or {}
    if not a:
        return cell.get("config_key") or cell.get("key", "?")
    return " ".join("%s=%s" % (k, v if isinstance(v, str) else json.dumps(v))
                    for k, v in a.items())


def repetition_sample(result):
    """The repetition's median step after the first, as `mcfbench compare` takes it."""
    t = (result.get("timing") or {}).get("step_median_seconds")
    if isinstance(t, (int, float)):
        return float(t)
    totals = [s["seconds"]["total"] for s in result.get("steps") or []
              if isinstance((s.get("seconds") or {}).get("total"), (int, float))]
    if len(totals) > 1:
        totals = totals[1:]
    return median(totals) if totals else None


def read_results(folder):
    out = []
    for name in sorted(os.listdir(folder)):
        if not name.endswith(".json") or name == "index.json":
            continue
        try:
            with open(os.path.join(folder, name)) as f:
                r = json.load(f)
        except (OSError, ValueError) as e:
            fail("%s: %s" % (os.path.join(folder, name), e))
        if isinstance(r, dict) and "cell" in r:
            out.append((name, r))
    return out


def read_results_of(folder, commit):
    """read_results(folder), only the results of `commit` (a prefix of either way) when given."""
    results = read_results(folder)
    if commit:
        results = [(n, r) for n, r in results
                   if str((r.get("environment") or {}).get("commit", "")).startswith(commit[:12])
                   or commit.startswith(str((r.get("environment") or {}).get("commit", "-")))]
    return results


def refuse_planted(path, environment):
    """A run slowed on purpose ($MCFBENCH_PLANTED_SLOWDOWN, scripts/history_aa_ab.sh) measured
    the plant, not the commit: it never enters a history."""
    if environment.get("planted_slowdown"):
        fail("%s: ran with a planted slowdown of %s (MCFBENCH_PLANTED_SLOWDOWN); not stored" %
             (path, environment["planted_slowdown"]))


def store_result_set(store, config_name, results_dir, info, commit=""):
    """Stores the cell results of `results_dir` (only those of `commit` when given) as the entry
    of commit info['commit']; returns the entry. All cells must share one machine identity
    (else they are not one series)."""
    results = read_results_of(results_dir, commit)
    if not results:
        fail("%s: no cell results%s" % (results_dir, " of " + commit if commit else ""))
    identity = machine_identity(results[0][1])
    benchmarks = {}
    for name, r in results:
        refuse_planted(os.path.join(results_dir, name), r.get("environment") or {})
        if machine_identity(r) != identity:
            fail("%s: cells of different machines, threads or builds in one set" % results_dir)
        cell = r["cell"]
        b = benchmarks.setdefault(cell_label(cell), {"key": cell.get("config_key", ""),
                                                     "samples": [], "contended": [],
                                                     "failed": 0})
        if r.get("status", "error") != "ok":
            b["failed"] += 1
        s = repetition_sample(r)
        if s is not None:
            b["samples"].append(s)
            b["contended"].append(bool((r.get("contention") or {}).get("contended")))

    def copy(target):
        if os.path.abspath(target) == os.path.abspath(results_dir):
            return
        shutil.rmtree(target, ignore_errors=True)
        os.makedirs(target)
        for name, _ in results:
            shutil.copy(os.path.join(results_dir, name), os.path.join(target, name))

    return write_entry(store, config_name, identity, benchmarks, info, copy)


def write_entry(store, config_name, identity, benchmarks, info, copy, metric="seconds.total"):
    """Writes STORE/<machine>/machine.json, the raw results (`copy(folder)`) and the entry
    STORE/<machine>/<config>/<commit>.json (atomically, last); returns the entry."""
    for b in benchmarks.values():
        # Repetitions that shared the machine with other work measured the machine as much as
        # the code: the median leaves them out while any repetition ran alone.
        quiet = [v for v, c in zip(b["samples"], b["contended"]) if not c]
        b["median"] = median(quiet or b["samples"]) if b["samples"] else None
    mid = machine_id(identity)
    folder = os.path.join(store, mid, config_name)
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(store, mid, "machine.json"), "w") as f:
        json.dump(identity, f, indent=1, sort_keys=True)
    copy(os.path.join(folder, info["commit"]))
    entry = dict(info, schema=1, config=config_name, machine=mid, metric=metric,
                 repetitions=max((len(b["samples"]) for b in benchmarks.values()), default=0),
                 benchmarks=benchmarks)
    tmp = os.path.join(folder, info["commit"] + ".json.tmp")
    with open(tmp, "w") as f:
        json.dump(entry, f, indent=1, sort_keys=True)
    os.replace(tmp, os.path.join(folder, info["commit"] + ".json"))
    return entry


# Google Benchmark's time units in seconds.
TIME_UNITS = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}


def micro_environment(path, data):
    """The mcfbench environment that mcfbench_micro writes into its context
    (benchmarks/micro_context.cpp): the same machine identity and commit as a result.json."""
    text = (data.get("context") or {}).get("mcfbench_environment")
    try:
        env = json.loads(text) if isinstance(text, str) else None
    except ValueError:
        env = None
    if not isinstance(env, dict):
        fail("%s: no context.mcfbench_environment (not mcfbench_micro's output, or a "
             "mcfbench_micro built before it recorded its machine)" % path)
    return env


def store_micro_set(store, config_name, path, info):
    """Stores a Google Benchmark JSON file of mcfbench_micro (benchmarks/run_micro.sh) as the
    entry of info['commit']: one benchmark per run name, one sample per repetition (its real
    time in seconds; aggregates are left out, they are functions of the repetitions). Benchmarks
    of an earlier entry of the same commit that this file did not run (another
    --benchmark_filter) are kept."""
    try:
        with open(path) as f:
            data = json.load(f)
    except (OSError, ValueError) as e:
        fail("%s: %s" % (path, e))
    env = micro_environment(path, data)
    refuse_planted(path, env)
    identity = {k: v for k, v in env.items() if k in IDENTITY_KEYS}
    benchmarks = {}
    for b in data.get("benchmarks") or []:
        if b.get("run_type", "iteration") != "iteration" or b.get("error_occurred"):
            continue
        unit = TIME_UNITS.get(b.get("time_unit", "ns"))
        if unit is None or not isinstance(b.get("real_time"), (int, float)):
            fail("%s: benchmark %s: no real_time in a known unit" % (path, b.get("name")))
        e = benchmarks.setdefault(b.get("run_name") or b["name"],
                                  {"key": b.get("run_name") or b["name"], "samples": [],
                                   "contended": [], "failed": 0})
        e["samples"].append(b["real_time"] * unit)
        e["contended"].append(False)
    if not benchmarks:
        fail("%s: no benchmark results" % path)
    earlier = find_entry(store, config_name, info["commit"], machine_id(identity))
    for name, b in ((earlier or {}).get("benchmarks") or {}).items():
        benchmarks.setdefault(name, b)

    def copy(target):
        os.makedirs(target, exist_ok=True)
        if os.path.abspath(os.path.dirname(path)) != os.path.abspath(target):
            shutil.copy(path, os.path.join(target, os.path.basename(path)))

    return write_entry(store, config_name, identity, benchmarks, info, copy,
                       metric="real_time")


def load_store(store):
    """{(machine, config): [entry, ...]} with every series in git order."""
    series = {}
    if not os.path.isdir(store):
        return series
    for mid in sorted(os.listdir(store)):
        mdir = os.path.join(store, mid)
        if not os.path.isdir(mdir):
            continue
        for config in sorted(os.listdir(mdir)):
            cdir = os.path.join(mdir, config)
            if not os.path.isdir(cdir):
                continue
            entries = []
            for name in os.listdir(cdir):
                if name.endswith(".json"):
                    with open(os.path.join(cdir, name)) as f:
                        entries.append(json.load(f))
            if entries:
                series[(mid, config)] = git_order(entries)
    return series


def git_order(entries):
    """Topological order of the entries by their recorded parents: a stored parent comes before
    its child; between entries not linked so (the commits between them were not stored), the
    commit date decides."""
    by = {e["commit"]: e for e in entries}
    children = {c: [] for c in by}
    indeg = {c: 0 for c in by}
    for e in entries:
        for p in e.get("parents", []):
            if p in by:
                children[p].append(e["commit"])
                indeg[e["commit"]] += 1
    ready = sorted((by[c]["date"], c) for c in by if indeg[c] == 0)
    out = []
    while ready:
        _, c = ready.pop(0)
        out.append(by[c])
        for k in children[c]:
            indeg[k] -= 1
            if indeg[k] == 0:
                ready.append((by[k]["date"], k))
                ready.sort()
    return out


def find_entry(store, config_name, commit, machine):
    if not machine:
        return None
    path = os.path.join(store, machine, config_name, commit + ".json")
    if os.path.isfile(path):
        with open(path) as f:
            return json.load(f)
    return None


# ----------------------------------------------------------------------------- running


def local_cpu():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "unknown"


def guess_machine(args):
    """The machine folder of this session before anything ran: --machine, else the only folder
    of the store holding this config whose CPU model and core count are this computer's (none
    when there are several, e.g. runs at different thread counts)."""
    if args.machine:
        return args.machine
    name, found = config_name_of(args.config), []
    if os.path.isdir(args.store):
        for mid in os.listdir(args.store):
            path = os.path.join(args.store, mid, "machine.json")
            if not (os.path.isfile(path) and os.path.isdir(os.path.join(args.store, mid, name))):
                continue
            with open(path) as f:
                m = json.load(f)
            if m.get("cpu") == local_cpu() and m.get("cores") == os.cpu_count():
                found.append(mid)
    return found[0] if len(found) == 1 else ""


def config_name_of(config):
    return os.path.splitext(os.path.basename(config))[0]


def is_micro_config(config):
    """A config of micro-benchmarks (benchmarks/configs/micro_quick.json): a JSON object with a
    "micro" key, run by mcfbench_micro rather than `mcfbench run`."""
    try:
        with open(config) as f:
            c = json.load(f)
    except (OSError, ValueError):
        return False  # the runner reports what is wrong with it
    return isinstance(c, dict) and "micro" in c


def store_run_output(store, config_name, out, info):
    """Stores what a runner left in `out`: mcfbench_micro's OUT/micro.json, else the cell results
    of `mcfbench run`."""
    micro = os.path.join(out, "micro.json")
    if os.path.isfile(micro):
        return store_micro_set(store, config_name, micro, info)
    return store_result_set(store, config_name, out, info)


class RunnerFailed(Exception):
    pass


def run_in(args, worktree, commit, out, repetitions, side=""):
    """Runs the runner in `worktree` (checked out at `commit`) into the folder `out`; `side`
    (base or head, for `ab`) goes to it as $MCFBENCH_HISTORY_SIDE."""
    env = dict(os.environ, MCFBENCH_HISTORY_COMMIT=commit,
               MCFBENCH_HISTORY_REPETITIONS=str(repetitions), MCFBENCH_HISTORY_SIDE=side)
    cmd = args.runner + " " + " ".join(shlex_quote(x) for x in (os.path.abspath(args.config),
                                                                os.path.abspath(out)))
    r = subprocess.run(cmd, shell=True, cwd=worktree, env=env)
    if r.returncode != 0:
        raise RunnerFailed("runner failed on %s (exit %d): %s" % (commit[:12], r.returncode, cmd))


def run_commit(args, commit, log):
    """Runs the runner in a worktree at `commit`; returns (work folder, results folder): the
    caller stores the results and removes the work folder."""
    work = tempfile.mkdtemp(prefix="mcfbench-history-")
    wt, out = os.path.join(work, "src"), os.path.join(work, "out")
    os.makedirs(out)
    git(args.repo, "worktree", "add", "--detach", "--force", wt, commit)
    log.append(commit)  # a failed run counts as a run too
    try:
        run_in(args, wt, commit, out, args.repetitions)
    except RunnerFailed:
        shutil.rmtree(work, ignore_errors=True)
        raise
    finally:
        git(args.repo, "worktree", "remove", "--force", wt)
    return work, out


def cmd_ab(args):
    """BASE and HEAD alternately on this machine, one repetition each per round, the order
    swapped every round (BASE HEAD, HEAD BASE, ...) so that a slow spell of the machine falls
    on both; then `COMPARE OUT/base OUT/head` decides: exit 0 no regression, 1 a regression,
    2 when it gave no verdict (it refuses sets of different machines, threads or builds).
    When any repetition of either side shared the machine with other work
    (`contention.contended`), its timings measured the machine as much as the code: the answer
    is then inconclusive (exit 3), whatever the comparison said."""
    commits = [git(args.repo, "rev-parse", c + "^{commit}") for c in (args.base, args.head)]
    work = tempfile.mkdtemp(prefix="mcfbench-ab-")
    trees = []
    try:
        for k, c in enumerate(commits):
            trees.append(os.path.join(work, "src%d" % k))
            git(args.repo, "worktree", "add", "--detach", "--force", trees[-1], c)
        for side in ("base", "head"):
            shutil.rmtree(os.path.join(args.out, side), ignore_errors=True)
            os.makedirs(os.path.join(args.out, side))
        for r in range(args.rounds):
            for k in ((0, 1) if r % 2 == 0 else (1, 0)):
                side = ("base", "head")[k]
                tmp = os.path.join(work, "round")
                shutil.rmtree(tmp, ignore_errors=True)
                os.makedirs(tmp)
                print("history ab: round %d/%d, %s %s" % (r + 1, args.rounds, side,
                                                          commits[k][:12]), file=sys.stderr)
                run_in(args, trees[k], commits[k], tmp, 1, side)
                # Each round's cells become one more repetition of the same cell keys.
                for name, res in read_results(tmp):
                    res["cell"]["repetition"] = r
                    with open(os.path.join(args.out, side, "r%03d-%s" % (r, name)), "w") as f:
                        json.dump(res, f)
    finally:
        for t in trees:
            subprocess.run(["git", "-C", args.repo, "worktree", "remove", "--force", t],
                           capture_output=True)
        shutil.rmtree(work, ignore_errors=True)
    # One comparison per metric: the whole step and each of its phases, so that a slowdown of
    # one phase is seen at its own size rather than diluted in the step (a 30% slower update is
    # a 10-20% slower step).
    status = 0
    for metric in args.metric or ["seconds.total"]:
        cmd = "%s %s %s --threshold %g --metric %s" % (
            args.compare, shlex_quote(os.path.join(args.out, "base")),
            shlex_quote(os.path.join(args.out, "head")), args.threshold, shlex_quote(metric))
        print("history ab: " + cmd, file=sys.stderr)
        r = subprocess.run(cmd, shell=True, stdout=subprocess.PIPE, text=True)
        print("## %s\n" % metric)
        sys.stdout.write(r.stdout)
        sys.stdout.flush()
        verdict = r.stdout.strip().split("\n")[-1] if r.stdout.strip() else ""
        if r.returncode not in (0, 1) or (r.returncode == 1 and verdict != "REGRESSION"):
            # The comparison gave no verdict (e.g. it refused sets whose machine, threads or
            # build differ): an error, never a regression.
            print("history ab: the comparison failed (exit %d) without a verdict" % r.returncode,
                  file=sys.stderr)
            return 2
        status = max(status, r.returncode)
    if status:
        print("REGRESSION")
    contended = contended_repetitions(args.out)
    if contended:
        print("INCONCLUSIVE: %d repetitions shared the machine with other work (%s); the "
              "comparison above is not a verdict on the code. Rerun on a quiet machine." %
              (len(contended), ", ".join(contended[:4]) + (" ..." if len(contended) > 4 else "")))
        return INCONCLUSIVE
    return status


# Exit status of `ab` (and of scripts/perf_gate.sh) when the machine was not quiet enough to
# judge: distinct from 0 (no regression), 1 (a regression) and 2 (usage or run errors).
INCONCLUSIVE = 3


def contended_repetitions(out):
    """'side/file' of each cell result under OUT/base and OUT/head whose contention.contended
    is true."""
    found = []
    for side in ("base", "head"):
        for name, r in read_results(os.path.join(out, side)):
            if (r.get("contention") or {}).get("contended"):
                found.append("%s/%s" % (side, name))
    return found


def shlex_quote(s):
    return shlex.quote(s)


def measure(args, commit, state, log):
    """The entry of `commit`: from the store when this machine already measured it, else run
    and stored. `state['machine']` is the machine of this session: guessed before the first
    run (guess_machine), known after it."""
    name = config_name_of(args.config)
    e = find_entry(args.store, name, commit, state.get("machine"))
    if e is not None and not args.force:
        print("history: %s from the store" % commit[:12], file=sys.stderr)
        return e
    print("history: running %s" % commit[:12], file=sys.stderr)
    work, out = run_commit(args, commit, log)
    try:
        e = store_run_output(args.store, name, out, commit_info(args.repo, commit))
    finally:
        shutil.rmtree(work, ignore_errors=True)
    state["machine"] = e["machine"]
    return e


def cmd_run(args):
    if args.last:
        commits = git(args.repo, "rev-list", "--first-parent", "-n", str(args.last),
                      args.range or "HEAD").split()[::-1]
    elif args.range and ".." in args.range:
        commits = commit_range(args.repo, args.range)
        # A..B leaves A out, as git does; the user named it, so it is measured too.
        commits = [git(args.repo, "rev-parse", args.range.split("..")[0] + "^{commit}")] + commits
    elif args.range:
        commits = [git(args.repo, "rev-parse", args.range + "^{commit}")]
    else:
        fail("run needs A..B, a commit or --last N")
    state, log, failed = {"machine": guess_machine(args)}, [], []
    for c in commits:
        # A commit that does not build or run leaves a gap in the series, not an end to it.
        try:
            measure(args, c, state, log)
        except RunnerFailed as e:
            print("history: " + str(e), file=sys.stderr)
            failed.append(c)
    print("history: %d commits, %d runs, %d failed%s; store %s" % (
        len(commits), len(log), len(failed),
        "".join(" " + c[:12] for c in failed), args.store))
    return 1 if failed else 0


def cmd_add(args):
    """Stores a result folder of `mcfbench run` (its cells; --commit picks one commit's of a
    shared folder), or a JSON file of mcfbench_micro, as the entry of the commit it measured."""
    if os.path.isfile(args.results):
        with open(args.results) as f:
            try:
                env = micro_environment(args.results, json.load(f))
            except ValueError as e:
                fail("%s: %s" % (args.results, e))
        commits = {env.get("commit")}
    elif os.path.isdir(args.results):
        commits = {(r.get("environment") or {}).get("commit")
                   for _, r in read_results_of(args.results, args.commit)}
    else:
        fail("%s: no such result folder or file" % args.results)
    commits.discard(None)
    if len(commits) != 1:
        fail("%s: results of %d commits (%s); one set per commit (--commit C picks one)" %
             (args.results, len(commits), " ".join(sorted(commits))))
    commit = commits.pop()
    if "dirty" in commit:
        fail("%s: results of uncommitted code (%s) have no place in a commit history" %
             (args.results, commit))
    try:
        info = commit_info(args.repo, commit)
    except subprocess.CalledProcessError:
        fail("%s: commit %s is not in the repository %s (--repo)" % (args.results, commit,
                                                                     args.repo))
    name = args.name or config_name_of(args.config)
    if os.path.isfile(args.results):
        e = store_micro_set(args.store, name, args.results, info)
    else:
        e = store_result_set(args.store, name, args.results, info, args.commit)
    print("history: stored %s under %s" % (info["commit"],
                                            os.path.join(args.store, e["machine"], name)))
    return 0


def cmd_bisect(args):
    """Binary search for the first commit of good..bad slower than `good` by more than half the
    threshold (or, when `bad` is in the store, than the geometric middle of the two). Runs good
    (unless stored) and one commit per halving: at most 1 + ceil(log2(len(good..bad))) when
    every commit runs.

    A commit whose runner fails (it does not build, or its run errors) is skipped, as
    `git bisect skip` does: the untested commit of the range nearest the middle is tried
    instead. When only skipped commits are left between the last good and the first bad one,
    the answer is that range (exit 3), not a guess."""
    candidates = commit_range(args.repo, args.good + ".." + args.bad)
    if not candidates:
        fail("%s..%s holds no commit" % (args.good, args.bad))
    good = git(args.repo, "rev-parse", args.good + "^{commit}")
    state, log = {"machine": guess_machine(args)}, []
    try:
        g = measure(args, good, state, log)
    except RunnerFailed as e:
        fail("the good end %s does not run, so nothing can be compared with it: %s" %
             (good[:12], e))
    names = [n for n, b in g["benchmarks"].items() if b["median"] and args.benchmark in n]
    if not names:
        fail("no benchmark of %s matches %r" % (good[:12], args.benchmark))
    cut = {n: g["benchmarks"][n]["median"] * (1 + args.threshold / 2) for n in names}
    b = find_entry(args.store, config_name_of(args.config), candidates[-1], state["machine"])
    if b:
        for n in names:
            if (b["benchmarks"].get(n) or {}).get("median"):
                cut[n] = math.sqrt(g["benchmarks"][n]["median"] * b["benchmarks"][n]["median"])

    def is_bad(entry):
        return any(((entry["benchmarks"].get(n) or {}).get("median") or 0) > cut[n]
                   for n in names)

    # The first bad commit lies in candidates[lo..hi]: candidates[hi] is bad (the bad end is
    # taken to be), everything before lo is good.
    lo, hi = 0, len(candidates) - 1
    verdicts, skipped = [], set()
    while lo < hi:
        untested = [i for i in range(lo, hi) if i not in skipped]
        if not untested:
            break
        middle = (lo + hi) // 2
        mid = min(untested, key=lambda i: (abs(i - middle), i))
        try:
            e = measure(args, candidates[mid], state, log)
        except RunnerFailed as err:
            print("history: skipped %s: %s" % (candidates[mid][:12], err), file=sys.stderr)
            skipped.add(mid)
            verdicts.append({"commit": candidates[mid], "skipped": True})
            continue
        bad = is_bad(e)
        verdicts.append({"commit": candidates[mid], "bad": bad,
                         "medians": {n: e["benchmarks"].get(n, {}).get("median") for n in names}})
        if bad:
            hi = mid
        else:
            lo = mid + 1
    report = {"runs": len(log), "run_commits": log, "good": good, "verdicts": verdicts,
              "cut": cut, "skipped": [candidates[i] for i in sorted(skipped)]}
    if lo == hi:
        first = candidates[lo]
        info = commit_info(args.repo, first)
        report.update(first_bad=first, subject=info["subject"], candidates=[first])
        print("first bad commit: %s %s" % (first, info["subject"]))
        status = 0
    else:
        # Only skipped commits lie before candidates[hi]: any of lo..hi can be the first bad.
        ambiguous = candidates[lo:hi + 1]
        report.update(first_bad=None, candidates=ambiguous)
        print("the first bad commit is one of %d (the commits before the last could not be "
              "run):" % len(ambiguous))
        for c in ambiguous:
            print("  %s %s%s" % (c, commit_info(args.repo, c)["subject"],
                                 "  (skipped)" if candidates.index(c) in skipped else ""))
        status = 3
    if args.json:
        with open(args.json, "w") as f:
            json.dump(report, f, indent=1)
    print("%d runs (of %d commits in the range), %d skipped" % (len(log), len(candidates),
                                                                len(skipped)))
    return status


# ----------------------------------------------------------------------------- detection


def series_steps(entries, threshold, alpha, min_run):
    """{benchmark: (points, steps)}: points = [(entry, median, samples, contended flags)] in git
    order."""
    out = {}
    names = sorted({n for e in entries for n in e["benchmarks"]})
    for n in names:
        pts = [(e, e["benchmarks"][n]["median"], e["benchmarks"][n]["samples"],
                e["benchmarks"][n].get("contended") or []) for e in entries
               if n in e["benchmarks"] and e["benchmarks"][n].get("median")]
        steps = detect_steps([p[1] for p in pts], threshold=threshold, alpha=alpha,
                             min_run=min_run)
        for s in steps:
            s["commit"] = pts[s["index"]][0]["commit"]
            s["previous"] = pts[s["index"] - 1][0]["commit"]
            # Commits between the two were not measured: the step lies somewhere in between.
            s["adjacent"] = s["previous"] in pts[s["index"]][0].get("parents", [])
            s["subject"] = pts[s["index"]][0].get("subject", "")
        out[n] = (pts, steps)
    return out


def all_steps(args):
    found = []
    for (mid, config), entries in load_store(args.store).items():
        for name, (pts, steps) in series_steps(entries, args.threshold, args.alpha,
                                               args.min_run).items():
            for s in steps:
                found.append(dict(s, machine=mid, config=config, benchmark=name))
    return found


def cmd_detect(args):
    steps = all_steps(args)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(steps, f, indent=1)
    if not steps:
        print("no step change in %s" % args.store)
        return 0
    print("| machine | config | benchmark | commit | previous measured | before | after | ratio "
          "| confidence |\n|---|---|---|---|---|---|---|---|---|")
    for s in steps:
        print("| %s | %s | %s | %s | %s | %.4g | %.4g | %.3f%s | %.3f |" % (
            s["machine"], s["config"], s["benchmark"], s["commit"][:12], s["previous"][:12],
            s["before"], s["after"], s["ratio"], " **slower**" if s["ratio"] > 1 else "",
            s["confidence"]))
    for s in steps:
        if not s["adjacent"] and s["ratio"] > 1:
            print("\n%s: commits between %s and %s were not measured; to name the first slow "
                  "one:\n  scripts/history.sh bisect CONFIG --good %s --bad %s --store %s" % (
                      s["benchmark"], s["previous"][:12], s["commit"][:12], s["previous"][:12],
                      s["commit"][:12], args.store))
    return 1 if args.fail_on_regression and any(s["ratio"] > 1 for s in steps) else 0


# ----------------------------------------------------------------------------- dashboard


def svg_chart(pts, steps, width=640, height=220):
    """An inline SVG: per commit its repetitions (dots) and median (line), each step a dashed
    vertical line labelled with its commit and ratio. Rendered here, so the page needs no
    script or network."""
    ml, mr, mt, mb = 56, 10, 14, 28
    vals = [v for _, m, s, _ in pts for v in (s or [m])]
    lo, hi = min(vals), max(vals)
    if hi <= lo:
        hi = lo * 1.1 + 1e-12
    pad = 0.08 * (hi - lo)
    lo, hi = lo - pad, hi + pad
    n = len(pts)

    def X(i):
        return ml + (width - ml - mr) * (0.5 if n == 1 else i / (n - 1))

    def Y(v):
        return mt + (height - mt - mb) * (1 - (v - lo) / (hi - lo))

    o = ['<svg class="chart" xmlns="http://www.w3.org/2000/svg" width="%d" height="%d" '
         'viewBox="0 0 %d %d" role="img">' % (width, height, width, height),
         '<rect x="%d" y="%d" width="%d" height="%d" fill="#fafafa" stroke="#ccc"/>' %
         (ml, mt, width - ml - mr, height - mt - mb)]
    for k in range(5):
        v = lo + (hi - lo) * k / 4
        o.append('<text x="%d" y="%.1f" font-size="10" text-anchor="end">%.4g</text>' %
                 (ml - 4, Y(v) + 3, v))
    for s in steps:
        x = 0.5 * (X(s["index"] - 1) + X(s["index"]))
        color = "#c00" if s["ratio"] > 1 else "#080"
        o.append('<line class="step" x1="%.1f" x2="%.1f" y1="%d" y2="%d" stroke="%s" '
                 'stroke-dasharray="4 3"/>' % (x, x, mt, height - mb, color))
        o.append('<text x="%.1f" y="%d" font-size="10" fill="%s">%s %+.0f%%</text>' %
                 (x + 3, mt + 11, color, s["commit"][:8], 100 * (s["ratio"] - 1)))
    for i, (e, m, samples, contended) in enumerate(pts):
        for k, v in enumerate(samples):
            if k < len(contended) and contended[k]:  # hollow: shared the machine
                o.append('<circle class="contended" cx="%.1f" cy="%.1f" r="2.2" fill="none" '
                         'stroke="#c80"/>' % (X(i), Y(v)))
            else:
                o.append('<circle cx="%.1f" cy="%.1f" r="1.8" fill="#99b"/>' % (X(i), Y(v)))
    o.append('<polyline class="series" fill="none" stroke="#225" stroke-width="1.5" '
             'points="%s"/>' % " ".join("%.1f,%.1f" % (X(i), Y(p[1])) for i, p in
                                        enumerate(pts)))
    step = max(1, n // 8)
    for i in range(0, n, step):
        o.append('<text x="%.1f" y="%d" font-size="9" text-anchor="middle">%s</text>' %
                 (X(i), height - 10, html.escape(pts[i][0]["commit"][:7])))
    o.append("</svg>")
    return "\n".join(o)


# Counts the charts that the browser laid out with a non-empty series line; a test reads the
# count back from the DOM. The page shows everything without it.
RENDER_CHECK = """<script>
addEventListener('load', function () {
  var n = 0;
  document.querySelectorAll('svg.chart').forEach(function (s) {
    var r = s.getBoundingClientRect(), p = s.querySelector('polyline.series');
    if (r.width > 0 && r.height > 0 && p && p.getTotalLength() > 0) n++;
  });
  document.body.setAttribute('data-charts-rendered', String(n));
});
</script>"""


def study_reports(args):
    """The reports the page links: --report PATHs, else the repository's own (docs/studies.md,
    which answers each study, and the reports of full runs kept under data/results/)."""
    if args.report:
        return args.report
    found = [os.path.join(args.repo, "docs", "studies.md")]
    found += sorted(os.path.join(d, f)
                    for d, _, files in os.walk(os.path.join(args.repo, "data", "results"))
                    for f in files if f.endswith(".md"))
    return [p for p in found if os.path.isfile(p)]


def report_links(args):
    """<li> items linking each study report, relative to the page (the page stays offline)."""
    items = []
    for path in study_reports(args):
        href = os.path.relpath(os.path.abspath(path), os.path.abspath(args.out))
        label = os.path.relpath(os.path.abspath(path), args.repo) \
            if os.path.abspath(path).startswith(os.path.abspath(args.repo) + os.sep) else path
        items.append('<li><a href="%s">%s</a></li>' % (html.escape(href), html.escape(label)))
    return "\n".join(items) or "<li>none given (--report PATH)</li>"


def cmd_publish(args):
    series = load_store(args.store)
    os.makedirs(args.out, exist_ok=True)
    regressions, sections, charts = [], [], 0
    for (mid, config), entries in series.items():
        machine = {}
        mpath = os.path.join(args.store, mid, "machine.json")
        if os.path.isfile(mpath):
            with open(mpath) as f:
                machine = json.load(f)
        sections.append('<h2 id="%s">%s — %s</h2>\n<p class="machine">%s</p>' % (
            html.escape(mid + "-" + config), html.escape(config), html.escape(mid),
            html.escape(", ".join("%s: %s" % (k, json.dumps(machine[k]) if not
                                              isinstance(machine[k], str) else machine[k])
                                  for k in sorted(machine)))))
        for name, (pts, steps) in series_steps(entries, args.threshold, args.alpha,
                                               args.min_run).items():
            if not pts:
                continue
            charts += 1
            sections.append('<div class="bench"><h3>%s</h3>\n%s</div>' %
                            (html.escape(name), svg_chart(pts, steps)))
            for s in steps:
                if s["ratio"] > 1:
                    regressions.append(dict(s, machine=mid, config=config, benchmark=name))
    regressions.sort(key=lambda s: -s["ratio"])
    rows = "\n".join(
        '<tr class="regression"><td>%s</td><td>%s</td><td>%s</td><td><code>%s</code> %s</td>'
        '<td>%+.1f%%</td><td>%.3f</td></tr>' % (
            html.escape(s["machine"]), html.escape(s["config"]), html.escape(s["benchmark"]),
            s["commit"][:12], html.escape(s.get("subject", "")), 100 * (s["ratio"] - 1),
            s["confidence"]) for s in regressions)
    page = """<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>mcfbench performance history</title>
<style>body{font-family:sans-serif;margin:1.5em;max-width:1100px}
table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:2px 6px;font-size:13px}
.bench{display:inline-block;margin:4px}.bench h3{font-size:13px;margin:2px 0}
.machine{color:#555;font-size:12px}</style></head>
<body>
<h1>mcfbench performance history</h1>
<p>Store: %s. Each chart: one benchmark on one machine, commits in git order; dots are
repetitions (median step after the first; hollow orange: other work shared the machine), the
line the commit medians (contended repetitions left out while any ran alone), in seconds; dashed
lines mark detected steps (red: slower, green: faster).</p>
<h2>Regressions</h2>
<table id="regressions"><tr><th>machine</th><th>config</th><th>benchmark</th><th>first slow
commit</th><th>change</th><th>confidence</th></tr>
%s
</table>
<p>%d regressions, %d charts.</p>
<h2>Study reports</h2>
<ul id="reports">
%s
</ul>
%s
%s
</body></html>
""" % (html.escape(args.store), rows, len(regressions), charts, report_links(args),
       "\n".join(sections), RENDER_CHECK)
    with open(os.path.join(args.out, "index.html"), "w") as f:
        f.write(page)
    print("wrote %s (%d charts, %d regressions)" % (os.path.join(args.out, "index.html"), charts,
                                                    len(regressions)))
    return 0


# ----------------------------------------------------------------------------- command line


def main(argv):
    try:
        return dispatch(argv)
    except RunnerFailed as e:
        fail(str(e))


def dispatch(argv):
    ap = argparse.ArgumentParser(prog="history", description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="command", required=True)

    def common(p):
        p.add_argument("--store", default="data/history", help="history folder")
        p.add_argument("--repo", default=".", help="git repository of the commits")

    def detector(p):
        p.add_argument("--threshold", type=float, default=0.1,
                       help="smallest relative step reported (default 0.1)")
        p.add_argument("--alpha", type=float, default=0.01,
                       help="significance of the U test between levels (default 0.01)")
        p.add_argument("--min-run", type=int, default=2,
                       help="commits a level needs on each side of a step (default 2)")

    def runner(p):
        p.add_argument("--runner", default="",
                       help="command run in a commit's worktree as `RUNNER CONFIG OUT` "
                       "(default scripts/history_runner.sh, for a micro-benchmark config "
                       "scripts/history_micro_runner.sh)")
        p.add_argument("--repetitions", type=int, default=5,
                       help="repetitions of each cell (default 5)")
        p.add_argument("--machine", default="",
                       help="machine folder of the store to reuse results from before the "
                       "first run (default: the only one with this CPU and core count)")
        p.add_argument("--force", action="store_true", help="rerun commits already stored")

    p = sub.add_parser("run", help="run and store commits A..B (A included), one commit or the "
                       "last N; a commit whose runner fails is skipped (exit 1 at the end)")
    p.add_argument("config")
    p.add_argument("range", nargs="?", default="")
    p.add_argument("--last", type=int, default=0)
    common(p)
    runner(p)
    p = sub.add_parser("add", help="store a result folder measured elsewhere, or a JSON file of "
                       "mcfbench_micro")
    p.add_argument("config", help="the config (its file name names the series) or a name")
    p.add_argument("results", help="a result folder of `mcfbench run`, or mcfbench_micro's JSON")
    p.add_argument("--name", default="", help="config name (default: CONFIG's file name)")
    p.add_argument("--commit", default="",
                   help="store only the results of this commit (a folder holding several)")
    common(p)
    p = sub.add_parser("detect", help="step changes of every stored series")
    common(p)
    detector(p)
    p.add_argument("--json", default="", help="also write the steps to this file")
    p.add_argument("--fail-on-regression", action="store_true",
                   help="exit 1 when a step is a slowdown")
    p = sub.add_parser("bisect", help="first commit of GOOD..BAD slower than GOOD; commits that "
                       "do not build or run are skipped (exit 3 when only skipped ones are left "
                       "and the answer is a range)")
    p.add_argument("config")
    p.add_argument("--good", required=True)
    p.add_argument("--bad", required=True)
    p.add_argument("--threshold", type=float, default=0.1,
                   help="smallest slowdown looked for (commits beyond half of it count as bad)")
    p.add_argument("--benchmark", default="", help="only benchmarks whose name holds this")
    p.add_argument("--json", default="", help="also write the outcome to this file")
    common(p)
    runner(p)
    p = sub.add_parser("ab", help="BASE and HEAD alternated over rounds, then compared (exit 0 "
                       "pass, 1 regression, 3 inconclusive: a repetition shared the machine)")
    p.add_argument("config")
    p.add_argument("base")
    p.add_argument("head")
    p.add_argument("--rounds", type=int, default=5, help="repetitions of each side (default 5)")
    p.add_argument("--out", required=True, help="folder for OUT/base and OUT/head")
    p.add_argument("--threshold", type=float, default=0.1,
                   help="relative slowdown that fails (default 0.1)")
    p.add_argument("--compare", default=shlex_quote(os.path.join(ROOT, "build", "mcfbench")) +
                   " compare", help="the comparison command (default build/mcfbench compare)")
    p.add_argument("--metric", action="append", default=[],
                   help="a per-step metric to compare (repeatable; default seconds.total); a "
                   "regression in any is one")
    common(p)
    runner(p)
    p = sub.add_parser("publish", help="write OUT/index.html")
    p.add_argument("out")
    p.add_argument("--report", action="append", default=[],
                   help="a study report to link (repeatable; default: the repository's "
                   "docs/studies.md and the Markdown reports under data/results/)")
    common(p)
    detector(p)
    args = ap.parse_args(argv)
    if hasattr(args, "repo"):
        try:
            args.repo = git(args.repo, "rev-parse", "--show-toplevel")
        except subprocess.CalledProcessError:
            if args.command in ("run", "add", "bisect"):
                fail("%s: not a git repository" % args.repo)
    if getattr(args, "runner", None) == "":
        micro = is_micro_config(args.config)
        if micro and args.command == "ab":
            fail("%s: ab compares result sets of `mcfbench run` (mcfbench compare); two builds' "
                 "micro-benchmarks compare with Google Benchmark's compare.py" % args.config)
        args.runner = "bash " + shlex_quote(MICRO_RUNNER if micro else DEFAULT_RUNNER)
    return {"run": cmd_run, "add": cmd_add, "detect": cmd_detect, "bisect": cmd_bisect,
            "ab": cmd_ab, "publish": cmd_publish}[args.command](args)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
