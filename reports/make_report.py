#!/usr/bin/python3
"""Regenerate the studies' figures and tables from result folders.

usage: /usr/bin/python3 reports/make_report.py RESULTS_DIR [RESULTS_DIR ...] OUT_DIR
                                               [--references harness/configs] [--require-complete]

Each results folder holds one study's result JSON files (index.json ignored); results are
grouped by cell.study and handed to the study's module; frames strips are drawn for any study
whose cells saved frames; OUT_DIR/index.md links everything. Nothing is rerun.

The cells `mcfbench run` planned (RESULTS_DIR/plans/, written before its first cell) are checked
against the results: a study whose planned cells do not all have a result yet (a run stopped or
still going) is warned about ("k of N cells have results"), its missing cells are listed in
index.md and its figures and tables are marked "incomplete: k of N cells". Folders without plans
are reported as before. --require-complete writes nothing and exits 1 instead when a planned
cell has no result or a cell errored.

Where results of several commits fill the same cell, the newest commit's (by file time) are
reported and the others left out, with a warning and a note in index.md naming the commits.
"""

import argparse
import contextlib
import importlib
import os
import shutil
import sys
import traceback

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import common  # noqa: E402
import index  # noqa: E402
import study_manifest  # noqa: E402

# Hidden (index.md links nothing in it), and removed by the next report into OUT_DIR when a killed
# report left it.
STAGING_FOLDER = ".report-staging"

# The studies with a report module of their name, in the report's order (harness/configs/studies.json).
STUDIES = study_manifest.names()


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("paths", nargs="+", metavar="DIR", help="results folder(s), then the output folder")
    p.add_argument("--references", default=common.DEFAULT_REFERENCES,
                   help="folder of <study>.reference.json paper values (default: harness/configs)")
    p.add_argument("--require-complete", action="store_true",
                   help="write nothing and exit 1 if a planned cell has no result, a cell errored, a "
                        "plan is unreadable or a results folder is missing or empty")
    args = p.parse_args(argv)
    if len(args.paths) < 2:
        p.error("need at least one RESULTS_DIR and an OUT_DIR")
    return args


def run_module(name, results, out_dir, reference, written):
    """Call module `name`.make; a failing module is reported, never fatal for the others. A file
    that cannot be written (common.WriteError) stops the whole report."""
    try:
        importlib.import_module(name).make(results, out_dir, reference, written)
        return True
    except common.WriteError:
        raise
    except Exception:  # noqa: BLE001 - partial data must not stop the other studies
        common.warn("%s failed:\n%s" % (name, traceback.format_exc()))
        return False


def missing_cells(results, planned):
    """The planned cells ({identity: (quick, cell)}) that no result in `results` is; sorted."""
    have = {common.result_identity(r) for r in results}
    missing = [dict(cell, quick=quick) for ident, (quick, cell) in planned.items() if ident not in have]
    number = lambda v: v if isinstance(v, int) else -1  # noqa: E731 - a plan is read, not trusted
    return sorted(missing, key=lambda c: (c["quick"], number(c.get("index")), number(c.get("repetition"))))


def main(argv):
    args = parse_args(argv)
    *folders, out_dir = args.paths
    by_study = {}
    planned = {}  # study -> {cell identity: (quick, planned cell)}, merged over folders and shards
    problems = []  # what --require-complete refuses besides missing and errored cells

    def results_of(study, folder):
        """The study's result list, with `folder` recorded among its sources."""
        entry = by_study.setdefault(study, ([], []))
        if folder not in entry[1]:
            entry[1].append(folder)
        return entry[0]

    for folder in folders:
        if not os.path.isdir(folder):
            common.warn("no such results folder: %s" % folder)
            problems.append("no such results folder: %s" % folder)
            continue
        plans, unreadable = common.load_plans(folder)
        problems += ["unreadable plan %s" % p for p in unreadable]
        for plan in plans:
            study, quick = str(plan.get("study") or "flow"), bool(plan.get("quick", False))
            results_of(study, folder)
            for c in plan["cells"]:
                if isinstance(c, dict):
                    planned.setdefault(study, {}).setdefault(common.cell_identity(study, quick, c), (quick, c))
        results = common.load_results(folder)
        if not results and not plans:
            problems.append("%s: no results and no run plan" % folder)
        for r in results:
            results_of(common.study_of(r), folder).append(r)
    # Planned cells without a result: {study: {"have", "total", "missing": [cells], "quick_mixed"}}.
    gaps = {}
    for study, cells in planned.items():
        missing = missing_cells(by_study[study][0], cells)
        if missing:
            gaps[study] = {"have": len(cells) - len(missing), "total": len(cells), "missing": missing,
                           "quick_mixed": len({q for q, _ in cells.values()}) > 1}
    # Cells run by several commits (a rerun at a newer commit into the same folder): the newest
    # commit's results of each cell are reported, the others left out and named.
    commits = {}
    for study, (results, _) in by_study.items():
        kept, info = common.newest_commits(results)
        if info:
            results[:] = kept
            commits[study] = common.commits_note(study, info)
    if args.require_complete:
        for study in sorted(by_study):
            if study in gaps:
                problems.append("%s: %d of %d cells have results" % (study, gaps[study]["have"], gaps[study]["total"]))
            errored = sum(r.get("status") == "error" for r in by_study[study][0])
            if errored:
                problems.append("%s: %d cell(s) errored" % (study, errored))
        if problems:
            for p in problems:
                print("error: " + p, file=sys.stderr)
            print("error: --require-complete: the results are incomplete; nothing written "
                  "(rerun `mcfbench run`, or leave out --require-complete to report them as they are)", file=sys.stderr)
            return 1
    # The report is written into a hidden staging folder of OUT_DIR and moved into OUT_DIR once
    # every file is written, index.md last: a full disk or a read-only folder stops it with
    # OUT_DIR as it was (an earlier report whole), and a report never half-written.
    created = not os.path.isdir(out_dir)
    staging = os.path.join(out_dir, STAGING_FOLDER)
    try:
        try:
            os.makedirs(out_dir, exist_ok=True)
            shutil.rmtree(staging, ignore_errors=True)  # a killed report's
            os.makedirs(staging)
        except OSError as e:
            raise common.WriteError(e.filename or out_dir, e) from e
        with common.staged(staging, out_dir):
            ok = write_report(staging, by_study, gaps, commits, args.references)
            publish(staging, out_dir)
    except common.WriteError as e:
        shutil.rmtree(out_dir if created else staging, ignore_errors=True)
        print("error: %s; the report was not written and %s is as it was" % (e, out_dir), file=sys.stderr)
        return 1
    return 0 if ok else 1


def publish(staging, out_dir):
    """Move the staged report's files into OUT_DIR (renames: each appears whole), index.md last."""
    names = sorted(os.listdir(staging), key=lambda n: (n == "index.md", n))
    try:
        for name in names:
            os.replace(os.path.join(staging, name), os.path.join(out_dir, name))
        os.rmdir(staging)
    except OSError as e:
        raise common.WriteError(e.filename or out_dir, e) from e


def write_report(out_dir, by_study, gaps, commits, references):
    """Every study's figures and tables, its frame strips and index.md, into `out_dir`; False when
    a module failed (the others are still drawn)."""
    ok = True
    sections = []
    for study in sorted(by_study, key=lambda s: (STUDIES.index(s) if s in STUDIES else len(STUDIES), s)):
        results, src = by_study[study]
        written = []
        reference = common.load_reference(study, references)
        gap = gaps.get(study)
        print("%s: %d result file(s)%s" % (study, len(results), "" if reference is None else ", paper reference found"))
        if study in commits:
            common.warn(commits[study])
        if gap:
            common.warn("%s: %d of %d cells have results; its figures and tables lack the %d other planned "
                        "cell(s) (listed in index.md; `mcfbench run` computes them)"
                        % (study, gap["have"], gap["total"], len(gap["missing"])))
        mark = common.marked_incomplete(gap["have"], gap["total"]) if gap else contextlib.nullcontext()
        with mark:
            if not results:
                pass  # planned, nothing finished yet: the index says so
            elif study in STUDIES:
                ok &= run_module(study, results, out_dir, reference, written)
            elif any(common.series(r, "radial_error.rms")[0] for r in results):
                # Plain `mcfbench flow` runs or a new study: at least show the radial errors.
                import sphere_error
                try:
                    sphere_error.plot_radial_errors(results, out_dir, "%s_radial_error" % study,
                                                    "%s: radial error per step" % study, reference, written)
                except common.WriteError:
                    raise
                except Exception:  # noqa: BLE001
                    common.warn("radial error plot for %s failed:\n%s" % (study, traceback.format_exc()))
                    ok = False
            else:
                common.warn("no report module for study %r; frames only" % study)
        if results:  # a strip shows one cell: complete whatever the study lacks
            ok &= run_module("frames", results, out_dir, reference, written)
        # A cell whose flow threw has no steps: the figures cannot show it, so the index says so.
        errored = [r for r in results if r.get("status") == "error"]
        if errored:
            common.warn("%s: %d cell(s) errored and are missing from its figures (listed in index.md)"
                        % (study, len(errored)))
        sections.append((study, src, written, errored, gap, commits.get(study)))
    index.make(out_dir, sections)
    return ok


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
