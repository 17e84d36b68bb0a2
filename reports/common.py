#!/usr/bin/python3
"""Shared helpers for the report scripts: loading result files, labelling variants,
reference values, figure style and provenance sidecars.

Reports read result JSON only (docs/design.md "Layers"); nothing here runs a flow.
"""

import contextlib
import glob
import json
import math
import os
import sys
import time

import matplotlib

matplotlib.use("Agg")  # headless: reports run on build machines without a display
import matplotlib.pyplot as plt  # noqa: E402

DPI = 120
REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_REFERENCES = os.path.join(REPO_ROOT, "harness", "configs")

plt.rcParams.update({
    "figure.dpi": DPI,
    "savefig.dpi": DPI,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "axes.spines.top": False,
    "axes.spines.right": False,
    "legend.fontsize": 8,
    "legend.frameon": False,
    "font.size": 9,
})


def warn(msg):
    """Print a warning to stderr (reports keep going on partial data)."""
    print("warning: " + msg, file=sys.stderr)


def get(d, dotted, default=None):
    """d["a"]["b"] for dotted "a.b"; also accepts a literal dotted key; default when missing."""
    if not isinstance(d, dict):
        return default
    if dotted in d:
        return d[dotted]
    node = d
    for part in dotted.split("."):
        if not isinstance(node, dict) or part not in node:
            return default
        node = node[part]
    return node


def finite(x):
    """True for a real finite number (JSON null, NaN, inf and strings are not)."""
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def load_results(folder):
    """All result files of a results folder: `*.json` except index.json, or, when there are
    none, `**/result.json` (a folder of `mcfbench flow` outputs). Each dict gets `_path`
    (absolute file) and `_stem` (file stem, names its frames folder). Unreadable files and
    files without "config" are skipped with a warning."""
    paths = sorted(p for p in glob.glob(os.path.join(folder, "*.json"))
                   if os.path.basename(p) != "index.json")
    if not paths:
        paths = sorted(glob.glob(os.path.join(folder, "**", "result.json"), recursive=True))
    results = []
    for p in paths:
        try:
            with open(p) as f:
                r = json.load(f)
        except (OSError, ValueError) as e:
            warn("skipping %s: %s" % (p, e))
            continue
        if not isinstance(r, dict) or "config" not in r:
            warn("skipping %s: not a result file (no \"config\")" % p)
            continue
        r["_path"] = os.path.abspath(p)
        stem = os.path.splitext(os.path.basename(p))[0]
        if stem == "result":  # mcfbench flow output: the folder names the run
            stem = os.path.basename(os.path.dirname(p))
        r["_stem"] = stem
        r["_folder"] = os.path.abspath(folder)
        r["_mtime"] = os.path.getmtime(p)  # orders commits that share a folder (newest_commits)
        r.setdefault("steps", [])
        results.append(r)
    return results


PLAN_FOLDER = "plans"  # harness/runner.h kPlanFolder


def load_plans(folder):
    """The plans `mcfbench run` wrote into a results folder before its first cell
    (FOLDER/plans/*.json, the format `mcfbench collect` reads): a list of dicts with "study",
    "quick" and "cells" ([{"index", "repetition", "assignment"[, "hash"]}], every cell of the
    matrix, also in a shard's plan). A folder without plans (`mcfbench flow` outputs, copied
    results) gives []. Unreadable plan files are skipped with a warning and returned in the
    second list."""
    plans, unreadable = [], []
    for p in sorted(glob.glob(os.path.join(folder, PLAN_FOLDER, "*.json"))):
        try:
            with open(p) as f:
                plan = json.load(f)
        except (OSError, ValueError) as e:
            warn("skipping plan %s: %s" % (p, e))
            unreadable.append(p)
            continue
        if isinstance(plan, dict) and isinstance(plan.get("cells"), list):
            plan["_path"] = os.path.abspath(p)
            plans.append(plan)
    return plans, unreadable


def assignment_key(cell):
    """A cell's assignment as a comparable string (keys sorted)."""
    return json.dumps(cell.get("assignment") or {}, sort_keys=True)


def cell_identity(study, quick, cell):
    """What makes a planned cell and a result the same cell: study, quick flag, repetition and
    assignment (not the commit: a planned cell is there when any commit's result is; where several
    commits ran a cell, the figures draw the newest one's, newest_commits). Not the index: it is
    the cell's place in the expansion, which an edit of the config's exclusions shifts while the
    runner rightly keeps the finished cell."""
    cell = cell if isinstance(cell, dict) else {}
    return (study, bool(quick), cell.get("repetition", 0) or 0, assignment_key(cell))


def result_identity(result):
    """cell_identity of a result file (None for a plain `mcfbench flow` run, which no plan names)."""
    cell = result.get("cell")
    if not isinstance(cell, dict):
        return None
    return cell_identity(study_of(result), cell.get("quick", False), cell)


# (cells with a result, cells planned) while make_report draws a study that lacks planned cells:
# save_figure and save_markdown mark what they save "incomplete: 3 of 8 cells". None otherwise.
_incomplete = None


@contextlib.contextmanager
def marked_incomplete(have, total):
    """Within the block, every figure and table saved says that only `have` of the `total`
    cells planned have results."""
    global _incomplete
    before, _incomplete = _incomplete, (have, total)
    try:
        yield
    finally:
        _incomplete = before


def incomplete_note():
    """The mark, "incomplete: 3 of 8 cells", inside marked_incomplete; None outside."""
    return "incomplete: %d of %d cells" % _incomplete if _incomplete else None


def study_of(result):
    """The study a result belongs to: cell.study, else "flow" (a plain `mcfbench flow` run)."""
    return get(result, "cell.study") or "flow"


def assignment(result):
    """The cell's {dotted key: value} assignment; built from the config when missing."""
    a = get(result, "cell.assignment")
    if isinstance(a, dict) and a:
        return a
    cfg = result.get("config", {})
    keys = ["mesh", "flow", "basis", "octree.tracking", "octree.stabilization", "octree.depth",
            "octree.cubature", "octree.refine_input", "solver.name", "solver.cycles", "integrator", "extrapolate", "dt"]
    return {k: get(cfg, k) for k in keys if get(cfg, k) is not None}


def short_value(v):
    """Compact text for a config value (mesh paths lose their folders)."""
    if isinstance(v, float):
        return "%g" % v
    if isinstance(v, str) and "/" in v:
        return os.path.basename(v)
    return str(v)


def varying_keys(results, exclude=()):
    """Assignment keys whose values differ between results (sorted), minus `exclude`."""
    values = {}
    for r in results:
        for k, v in assignment(r).items():
            values.setdefault(k, set()).add(json.dumps(v, sort_keys=True))
    keys = [k for k, vs in values.items() if len(vs) > 1 or any(k not in assignment(r) for r in results)]
    return sorted(k for k in keys if k not in exclude)


def key_name(key):
    """A config key as a legend names it: its last component ("octree.depth" -> "depth"), or the
    one before a last component called "name" ("solver.name" -> "solver")."""
    parts = key.split(".")
    return parts[-2] if parts[-1] == "name" and len(parts) > 1 else parts[-1]


# Config sections that belong to one basis: their keys mean nothing in a cell of another basis.
BASIS_SECTIONS = ("octree",)


def applies(key, basis):
    """False for a key of a basis the cell does not use: a hat-basis cell of a zip beside octree
    cells carries "octree.tracking" too, but it changes nothing in that run."""
    section = key.split(".")[0]
    return not (section in BASIS_SECTIONS and isinstance(basis, str) and basis != section)


def label(result, keys):
    """Legend label: the values of `keys` in the result's assignment, "key=value" joined (a PETSc
    solver as the method it ran, "solver=petsc-cg-gamg"); a true
    flag is its key alone and a false one is left out ("tracking=rebuilt, refine_input" beside
    "tracking=rebuilt"), unless false flags are all there is to tell the variants apart. Keys of
    another basis are left out ("basis=hat, solver=pcg", not "tracking=tracked")."""
    a = assignment(result)
    basis = get(result, "config.basis", a.get("basis"))
    present = [k for k in keys if k in a and applies(k, basis)]
    def shown(k):
        # A PETSc cell names the method it ran ("solver=petsc-cg-gamg": CG with smoothed-
        # aggregation AMG), which its options, not its solver.name, chose.
        if k == "solver.name" and a[k] == "petsc" and isinstance(result.get("solver_name"), str):
            return result["solver_name"]
        return short_value(a[k])
    parts = [key_name(k) if a[k] is True else "%s=%s" % (key_name(k), shown(k))
             for k in present if a[k] is not False]
    if not parts:
        parts = ["%s=%s" % (key_name(k), short_value(a[k])) for k in present]
    return ", ".join(parts) if parts else short_value(get(result, "config.mesh", result["_stem"]))


def legend_beside(axes):
    """One legend for the whole figure, right of its panels, each label once. The panels of a
    figure plot the same variants, and a legend inside a panel hides the curves it names (the
    papers' log plots leave no empty corner)."""
    handles = {}
    for ax in axes:
        for h, text in zip(*ax.get_legend_handles_labels()):
            handles.setdefault(text, h)
    if handles:  # attached to the last panel, so it sits right beside it at any figure width
        axes[-1].legend(list(handles.values()), list(handles.keys()), loc="center left",
                        bbox_to_anchor=(1.02, 0.5))


def group_by(results, keyfunc):
    """Ordered {key: [results]} (first-seen order, repetitions stay together)."""
    groups = {}
    for r in results:
        groups.setdefault(keyfunc(r), []).append(r)
    return groups


def commit_of(result):
    """The commit that computed a result (environment.commit), "unknown" when it does not say."""
    return str(get(result, "environment.commit") or "unknown")


def config_identity(result):
    """Which configuration a result ran, repetitions aside: cell.config_key (harness/cell_hash.cpp:
    the full config and the mesh's fingerprint, without the repetition, as `mcfbench compare`
    pools repetitions), else (results without it) the cell's study, quick flag and assignment,
    else the file itself (a plain `mcfbench flow` run)."""
    cell = result.get("cell")
    if isinstance(cell, dict):
        if cell.get("config_key"):
            return ("config_key", str(cell["config_key"]))
        return ("cell",) + cell_identity(study_of(result), cell.get("quick", False), dict(cell, repetition=0))
    return ("file", result.get("_path", result.get("_stem")))


def cell_slot(result):
    """The cell a result fills in its study, whatever the commit: its quick flag and assignment
    (a commit that changes a default key or a generated mesh changes config_key, not the cell);
    a plain `mcfbench flow` run is its own slot."""
    cell = result.get("cell")
    if not isinstance(cell, dict):
        return ("file", result.get("_path", result.get("_stem")))
    return (study_of(result), bool(cell.get("quick", False)), assignment_key(cell))


def newest_commits(results):
    """Where results of several commits fill the same cell (a study rerun at a newer commit into
    the same folder), keep the newest commit's results of that cell, all its repetitions: a
    commit is as new as its newest result file (modification time; result.json records no date),
    ties broken by the commit's name. Returns (kept results in their order, None) for results of
    one commit, else (kept, {"commits": [(commit, newest file time, results kept, results left
    out)], newest first, "left_out": number of results left out})."""
    times = {}
    for r in results:
        c = commit_of(r)
        times[c] = max(times.get(c, float("-inf")), r.get("_mtime", 0.0))
    if len(times) <= 1:
        return list(results), None
    rank = {c: i for i, c in enumerate(sorted(times, key=lambda c: (times[c], c)))}
    newest = {}
    for r in results:
        slot, c = cell_slot(r), commit_of(r)
        if slot not in newest or rank[c] > rank[newest[slot]]:
            newest[slot] = c
    kept = [r for r in results if newest[cell_slot(r)] == commit_of(r)]
    counts = {c: [0, 0] for c in times}
    for r in results:
        counts[commit_of(r)][0 if newest[cell_slot(r)] == commit_of(r) else 1] += 1
    order = sorted(times, key=lambda c: -rank[c])
    return kept, {"commits": [(c, times[c], counts[c][0], counts[c][1]) for c in order],
                  "left_out": len(results) - len(kept)}


def commits_note(study, info):
    """One line on a study whose results came from several commits (newest_commits' info)."""
    parts = []
    for c, t, kept, left in info["commits"]:
        when = time.strftime("%Y-%m-%d %H:%M:%S", time.gmtime(t)) if finite(t) else "?"
        parts.append("%s (newest file %s UTC: %d result(s) kept%s)" % (
            c, when, kept, ", %d left out" % left if left else ""))
    return ("%s: results of %d commits: %s. Per cell the newest commit's results are drawn (%d older "
            "result(s) of the same cells left out)%s." % (
                study, len(info["commits"]), "; ".join(parts), info["left_out"],
                "; its figures and tables mix commits" if sum(1 for _, _, kept, _ in info["commits"] if kept) > 1 else ""))


def contended(result):
    """Whether the cell shared its cores with other work while it ran (`contention.contended`,
    harness/contention.h): its times are not a measurement of its method."""
    return bool(get(result, "contention.contended", False))


def quiet_or_all(results):
    """The repetitions that ran uncontended, or all of them where none did."""
    quiet = [r for r in results if not contended(r)]
    return quiet or list(results)


def time_text(result, seconds, spec="%.3g"):
    """A formatted time, marked where its cell was contended."""
    return fmt(seconds, spec) + (" (contended)" if contended(result) and finite(seconds) else "")


def by_configuration(results):
    """[(repetitions, quiet_timed)] per configuration (config_identity) of the newest commit:
    its repetitions in order, and of those the ones to time: the uncontended ones, or all where
    every one was contended."""
    groups = group_by(newest_commits(results)[0], config_identity)
    out = []
    for _, reps in sorted(groups.items(), key=lambda kv: str(kv[0])):
        reps = sorted(reps, key=lambda r: get(r, "cell.repetition", 0) or 0)
        out.append((reps, quiet_or_all(reps)))
    return out


def median_of(results, path):
    """The median of `path` over `results` where every one has it finite, else None."""
    return median([get(r, path) for r in results])


def median(values):
    """The median of `values` where every one is finite, else None."""
    if not values or not all(finite(v) for v in values):
        return None
    values = sorted(values)
    mid = len(values) // 2
    return values[mid] if len(values) % 2 else 0.5 * (values[mid - 1] + values[mid])


def first_repetition(results):
    """One result per configuration (config_identity) and commit, its lowest repetition: curves
    are drawn once per variant. Of cells run by several commits only the newest commit's results
    count (newest_commits; make_report warns about them)."""
    best = {}
    for r in newest_commits(results)[0]:
        key = (config_identity(r), commit_of(r))
        rep = get(r, "cell.repetition", 0) or 0
        if key not in best or rep < (get(best[key], "cell.repetition", 0) or 0):
            best[key] = r
    return sorted(best.values(), key=lambda r: (get(r, "cell.index", 0) or 0, r["_stem"]))


def series(result, path):
    """(steps, values) of steps[*].<path> where the value is finite."""
    xs, ys = [], []
    for i, s in enumerate(result.get("steps", []) or []):
        v = get(s, path)
        if finite(v):
            xs.append(s.get("step", i + 1))
            ys.append(v)
    return xs, ys


def is_singular(result):
    """Whether the run stopped at a singularity (or diverged/failed) rather than finishing."""
    return result.get("status") not in (None, "ok")


def load_reference(study, references_dir):
    """harness/configs/<study>.reference.json as a dict, or None when absent or unreadable."""
    if not references_dir:
        return None
    p = os.path.join(references_dir, study + ".reference.json")
    if not os.path.exists(p):
        return None
    try:
        with open(p) as f:
            return json.load(f)
    except (OSError, ValueError) as e:
        warn("ignoring %s: %s" % (p, e))
        return None


def reference_curves(reference):
    """Paper curves from a reference file: {"curves": {label: {"step": [...], <metric>: [...]}}}."""
    curves = (reference or {}).get("curves", {})
    return curves if isinstance(curves, dict) else {}


def plot_reference_curves(ax, reference, metric, xkey="step"):
    """Draw the paper's digitised curves for `metric` (grey, dotted) when the reference has them."""
    for name, c in reference_curves(reference).items():
        if isinstance(c, dict) and xkey in c and metric in c:
            ax.plot(c[xkey], c[metric], ":", color="0.5", lw=1.2, label="paper: " + str(name))


def log_if_positive(ax, values, axis="y"):
    """Log scale (as the papers use) only when every plotted value is positive."""
    vals = [v for v in values if finite(v)]
    if vals and min(vals) > 0:
        (ax.set_yscale if axis == "y" else ax.set_xscale)("log")


def sources_line(results, limit=6):
    """Caption text naming the result files a figure/table came from; long lists are shortened
    (the full list is always in the NAME.sources.txt sidecar) so the caption fits the figure."""
    names = [os.path.basename(r["_path"]) for r in results]
    if len(names) <= limit:
        return "Sources: " + ", ".join(names)
    return "Sources: %s, … (%d result files; full list in the .sources.txt beside this file)" % (
        ", ".join(names[:3]), len(names))


class WriteError(Exception):
    """A file of the report could not be written (a full disk, a read-only folder). Not a module's
    failure: make_report stops, removes what it wrote and leaves its output folder as it was."""

    def __init__(self, path, error):
        super().__init__("cannot write %s: %s" % (shown(path), getattr(error, "strerror", None) or error))
        self.path = shown(path)


# (staging folder, report folder) while make_report writes the report into a staging folder, which
# it moves into the report folder once everything is written. None otherwise.
_staged = None


@contextlib.contextmanager
def staged(staging, out_dir):
    """Within the block, paths under `staging` are named as the files they become in `out_dir`."""
    global _staged
    before, _staged = _staged, (staging, out_dir)
    try:
        yield
    finally:
        _staged = before


def shown(path):
    """`path` as it is named once the report is published (see staged)."""
    if _staged and os.path.dirname(path) == _staged[0]:
        return os.path.join(_staged[1], os.path.basename(path))
    return path


def write_text(path, text):
    """Write a text file of the report; an OSError becomes a WriteError naming the file."""
    try:
        with open(path, "w") as f:
            f.write(text)
    except OSError as e:
        raise WriteError(path, e) from e


def write_sources(out_path, results):
    """Write OUT.sources.txt beside a figure/table: one result file path per line."""
    side = os.path.splitext(out_path)[0] + ".sources.txt"
    write_text(side, "".join(r["_path"] + "\n" for r in results))
    return side


def save_figure(fig, out_dir, name, results, title, written):
    """Save a figure as OUT_DIR/NAME.png with its sources sidecar; record it in `written`."""
    os.makedirs(out_dir, exist_ok=True)
    path = os.path.join(out_dir, name + ".png")
    extra, note = {}, incomplete_note()
    if note:  # a red line above the title, and the PNG's Description
        fig.text(0.5, 1.0, note, ha="center", va="bottom", color="red", fontsize=10, fontweight="bold")
        title = "%s (%s)" % (title, note)
        extra["metadata"] = {"Description": note}
    try:
        fig.savefig(path, dpi=DPI, bbox_inches="tight", **extra)
    except OSError as e:
        raise WriteError(path, e) from e
    finally:
        plt.close(fig)
    write_sources(path, results)
    print("wrote " + shown(path))
    written.append({"path": path, "title": title, "kind": "figure"})
    return path


def save_markdown(text, out_dir, name, results, title, written):
    """Save OUT_DIR/NAME.md (with a sources caption line and sidecar); record it in `written`."""
    os.makedirs(out_dir, exist_ok=True)
    path = os.path.join(out_dir, name + ".md")
    if _incomplete:
        text = ("**Incomplete: %d of %d planned cells have results**; the missing cells are listed in "
                "index.md.\n\n" % _incomplete) + text
        title = "%s (%s)" % (title, incomplete_note())
    write_text(path, text.rstrip() + "\n\n" + sources_line(results) + "\n")
    write_sources(path, results)
    print("wrote " + shown(path))
    written.append({"path": path, "title": title, "kind": "table"})
    return path


def markdown_table(header, rows):
    """A Markdown table from a header list and rows of already formatted cells."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for row in rows:
        lines.append("| " + " | ".join(str(c) for c in row) + " |")
    return "\n".join(lines)


def fmt(x, spec="%.3g"):
    """Format a number; '—' for missing/non-finite."""
    return spec % x if finite(x) else "—"


def mark_stop(ax, result, xs, ys, color):
    """Mark a singular/diverged stop with an x at the last recorded point."""
    if is_singular(result) and xs:
        ax.plot([xs[-1]], [ys[-1]], "x", color=color, ms=8, mew=2)
        reason = get(result, "stop.reason", result.get("status"))
        ax.annotate(str(reason)[:24], (xs[-1], ys[-1]), fontsize=6, color=color,
                    xytext=(3, 3), textcoords="offset points")
